// CSV cell rules shared by the measurement and viewing-angle readers.
#include <cmath>
#include <sstream>
#include <stdexcept>

#include <pipeline/display/csv_cells.h>

namespace replica::pipeline::display {

std::string trimCell(const std::string& s)
{
    const auto b = s.find_first_not_of(" \t\r");
    if (b == std::string::npos) {
        return {};
    }
    const auto e = s.find_last_not_of(" \t\r");
    return s.substr(b, e - b + 1);
}

std::vector<std::string> splitCsvRow(const std::string& line)
{
    std::vector<std::string> out;
    std::string cell;
    std::istringstream in(line);
    while (std::getline(in, cell, ',')) {
        out.push_back(trimCell(cell));
    }
    if (!line.empty() && line.back() == ',') {
        out.emplace_back();
    }
    return out;
}

bool parseFiniteNumber(const std::string& s, double& v)
{
    if (s.empty()) {
        return false;
    }
    std::size_t used = 0;
    try {
        v = std::stod(s, &used);
    } catch (const std::exception&) {
        return false;
    }
    return used == s.size() && std::isfinite(v);
}

} // namespace replica::pipeline::display
