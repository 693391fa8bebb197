// CSV cell rules shared by every reader.
#include <charconv>
#include <cmath>

#include <pipeline/csv/csv_cells.h>

namespace replica::pipeline::csv {
namespace {

constexpr std::string_view kBlank = " \t\r";

} // namespace

std::string trimCell(std::string_view s)
{
    const auto b = s.find_first_not_of(kBlank);
    if (b == std::string_view::npos) {
        return {};
    }
    const auto e = s.find_last_not_of(kBlank);
    return std::string(s.substr(b, e - b + 1));
}

std::vector<std::string> splitCsvRow(std::string_view line)
{
    std::vector<std::string> out;
    std::size_t start = 0;
    while (true) {
        const auto comma = line.find(',', start);
        if (comma == std::string_view::npos) {
            out.push_back(trimCell(line.substr(start)));
            return out;
        }
        out.push_back(trimCell(line.substr(start, comma - start)));
        start = comma + 1;
    }
}

bool parseFiniteNumber(std::string_view cell, double& v)
{
    if (cell.empty()) {
        return false;
    }
    const char* first = cell.data();
    const char* last = cell.data() + cell.size();
    // from_chars takes a leading '-' but not '+': skip one '+', and refuse a second sign after
    // it ("+-1", which from_chars would read as -1).
    if (*first == '+') {
        ++first;
        if (first == last || *first == '-' || *first == '+') {
            return false;
        }
    }
    double parsed = 0.0;
    const auto [ptr, ec] = std::from_chars(first, last, parsed, std::chars_format::general);
    if (ec != std::errc() || ptr != last || !std::isfinite(parsed)) {
        return false;
    }
    v = parsed;
    return true;
}

} // namespace replica::pipeline::csv
