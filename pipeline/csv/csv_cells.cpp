// CSV cell rules shared by every reader.
#include <algorithm>
#include <charconv>
#include <cmath>
#include <sstream>

#include <pipeline/base/printable.h>
#include <pipeline/csv/csv_cells.h>

namespace replica::pipeline::csv {
namespace {

constexpr std::string_view kBlank = " \t\r";

} // namespace

std::string trimCell(std::string_view s)
{
    // A UTF-8 byte order mark (spreadsheet exports start the file with one) is not part of the
    // first cell.
    constexpr std::string_view kBom = "\xEF\xBB\xBF";
    if (s.substr(0, kBom.size()) == kBom) {
        s.remove_prefix(kBom.size());
    }
    const auto b = s.find_first_not_of(kBlank);
    if (b == std::string_view::npos) {
        return {};
    }
    const auto e = s.find_last_not_of(kBlank);
    return std::string(s.substr(b, e - b + 1));
}

std::vector<std::string> splitCsvRow(std::string_view line)
{
    // RFC 4180 quoting: a cell whose first non-blank character is '"' runs to the closing quote,
    // commas included, with "" for a quote inside; what follows the closing quote up to the next
    // comma is kept too (and then refused by whoever reads the cell as a number).
    std::vector<std::string> out;
    std::size_t p = 0;
    while (true) {
        std::size_t q = p;
        while (q < line.size() && kBlank.find(line[q]) != std::string_view::npos) {
            ++q;
        }
        constexpr std::string_view kBom = "\xEF\xBB\xBF";
        if (line.substr(q, kBom.size()) == kBom) {
            q += kBom.size();
        }
        if (q < line.size() && line[q] == '"') {
            std::string cell;
            std::size_t i = q + 1;
            for (; i < line.size(); ++i) {
                if (line[i] == '"') {
                    if (i + 1 < line.size() && line[i + 1] == '"') {
                        cell += '"';
                        ++i;
                        continue;
                    }
                    break;
                }
                cell += line[i];
            }
            const auto comma = line.find(',', std::min(i + 1, line.size()));
            const auto tail = line.substr(std::min(i + 1, line.size()),
                                          comma == std::string_view::npos
                                                  ? std::string_view::npos
                                                  : comma - std::min(i + 1, line.size()));
            cell += trimCell(tail);
            out.push_back(trimCell(cell));
            if (comma == std::string_view::npos) {
                return out;
            }
            p = comma + 1;
            continue;
        }
        const auto comma = line.find(',', p);
        if (comma == std::string_view::npos) {
            out.push_back(trimCell(line.substr(p)));
            return out;
        }
        out.push_back(trimCell(line.substr(p, comma - p)));
        p = comma + 1;
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

std::string shownCell(std::string_view cell)
{
    return printable(cell, kShownCellChars);
}

std::vector<CsvLine> csvLines(const std::string& text)
{
    std::vector<CsvLine> out;
    std::istringstream in(text);
    std::string raw;
    int number = 0;
    while (std::getline(in, raw)) {
        ++number;
        std::string line = trimCell(raw);
        if (line.empty() || line[0] == '#') {
            continue;
        }
        auto cells = splitCsvRow(line);
        out.push_back({number, std::move(line), std::move(cells)});
    }
    return out;
}

} // namespace replica::pipeline::csv
