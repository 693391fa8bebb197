// 'replica color de2000 PAIRS.csv': CIEDE2000 of each CIELAB pair in a CSV file.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <pipeline/base/expected.h>
#include <pipeline/base/input_file.h>
#include <pipeline/colour/ciede2000.h>
#include <pipeline/csv/csv_cells.h>
#include <platform/cli/commands.h>

namespace replica::platform {
namespace {

using pipeline::colour::Lab;

struct PairRow {
    int line = 0;
    std::string text;
    Lab lab1;
    Lab lab2;
};

struct PairFile {
    std::string header;
    std::vector<PairRow> rows;
};

// CIELAB as a colour can have it, widely: L* from 0 (black) to 1000 (100 is the white point, and a
// highlight may be a little above it), a* and b* within +-1000 (the spectrum locus reaches about
// +-500). Beyond that the formula's powers overflow: L* = 1e200 gave a dE00 of NaN.
constexpr double kMaxLightness = 1000.0;
constexpr double kMaxChroma = 1000.0;

Expected<void> checkLabRange(double v, bool lightness, const std::string& cell, const char* column)
{
    const double lo = lightness ? 0.0 : -kMaxChroma;
    const double hi = lightness ? kMaxLightness : kMaxChroma;
    if (v >= lo && v <= hi) {
        return {};
    }
    return makeError(ErrorCode::InvalidArgument,
                     fmt::format("column '{}' value '{}' is outside [{:g}, {:g}] ({}); fix or "
                                 "remove the row",
                                 column, pipeline::csv::shownCell(cell), lo, hi,
                                 lightness ? "L*: 0 is black, 100 the white point"
                                           : "a*, b*: the spectrum locus is within +-500"));
}

Expected<PairFile> readPairs(const std::string& path)
{
    // Regular files only, opened once and read whole within the CSV limits: a directory would
    // throw from a stream, a FIFO block it, /dev/zero fill memory.
    auto text = readInputFile(path, kMaxCsvBytes, "CSV");
    if (!text) {
        if (text.error().code == ErrorCode::NotFound) {
            return makeError(ErrorCode::NotFound,
                             fmt::format("{}: cannot open (does the file exist?)", path));
        }
        return tl::unexpected(text.error());
    }
    if (auto ok = checkTableLimits(*text, path, ','); !ok) {
        return tl::unexpected(ok.error());
    }
    std::istringstream file(std::move(*text));
    static const char* const kColumns[6] = {"L1", "a1", "b1", "L2", "a2", "b2"};
    PairFile out;
    std::size_t columnIndex[6] = {};
    std::size_t width = 0;
    bool haveHeader = false;
    std::string line;
    int lineNo = 0;
    while (std::getline(file, line)) {
        ++lineNo;
        if (!line.empty() && line.back() == '\r') {
            line.pop_back();
        }
        if (line.empty() || line[0] == '#') {
            continue;
        }
        const auto cells = pipeline::csv::splitCsvRow(line);
        if (!haveHeader) {
            for (std::size_t c = 0; c < 6; ++c) {
                const auto it = std::find(cells.begin(), cells.end(), kColumns[c]);
                if (it == cells.end()) {
                    return makeError(
                            ErrorCode::InvalidArgument,
                            fmt::format(
                                    "{}:{}: header has no column '{}' (expected L1,a1,b1,L2,a2,b2)",
                                    path, lineNo, kColumns[c]));
                }
                columnIndex[c] = static_cast<std::size_t>(it - cells.begin());
            }
            width = cells.size();
            out.header = line;
            haveHeader = true;
            continue;
        }
        if (cells.size() != width) {
            return makeError(ErrorCode::InvalidArgument,
                             fmt::format("{}:{}: {} cells, expected {} as in the header", path,
                                         lineNo, cells.size(), width));
        }
        double v[6] = {};
        for (std::size_t c = 0; c < 6; ++c) {
            const std::string& cell = cells[columnIndex[c]];
            if (!pipeline::csv::parseFiniteNumber(cell, v[c])) {
                return makeError(ErrorCode::InvalidArgument,
                                 fmt::format("{}:{}: column '{}' value '{}' is not a finite number",
                                             path, lineNo, kColumns[c],
                                             pipeline::csv::shownCell(cell)));
            }
            if (auto ok = checkLabRange(v[c], c % 3 == 0, cell, kColumns[c]); !ok) {
                return makeError(ErrorCode::InvalidArgument,
                                 fmt::format("{}:{}: {}", path, lineNo, ok.error().message));
            }
        }
        out.rows.push_back(PairRow{lineNo, line, Lab{v[0], v[1], v[2]}, Lab{v[3], v[4], v[5]}});
    }
    if (!haveHeader) {
        return makeError(ErrorCode::InvalidArgument,
                         fmt::format("{}: no header line 'L1,a1,b1,L2,a2,b2' found", path));
    }
    return out;
}

} // namespace

void registerColorCommand(CLI::App& app, int& exitCode)
{
    auto* color = app.add_subcommand("color", "colorimetry calculations");
    color->require_subcommand(1);
    auto* de = color->add_subcommand("de2000", "CIEDE2000 of CIELAB pairs: reads a CSV with header "
                                               "columns L1,a1,b1,L2,a2,b2 and prints "
                                               "the same rows with a de00 column");
    auto path = std::make_shared<std::string>();
    auto json = std::make_shared<bool>(false);
    de->add_option("PAIRS.csv", *path, "CSV file of pairs")->required();
    de->add_flag("--json", *json, "print JSON ({\"pairs\": [...]}) instead of CSV");
    de->callback([path, json, &exitCode] {
        auto pairs = readPairs(*path);
        if (!pairs) {
            std::fprintf(stderr, "replica color de2000: %s\n", pairs.error().message.c_str());
            exitCode = kExitFailure;
            return;
        }
        if (*json) {
            nlohmann::json out;
            out["pairs"] = nlohmann::json::array();
            for (const auto& r : pairs->rows) {
                out["pairs"].push_back({{"line", r.line},
                                        {"L1", r.lab1.L},
                                        {"a1", r.lab1.a},
                                        {"b1", r.lab1.b},
                                        {"L2", r.lab2.L},
                                        {"a2", r.lab2.a},
                                        {"b2", r.lab2.b},
                                        {"de00", pipeline::colour::ciede2000(r.lab1, r.lab2)}});
            }
            std::cout << out.dump(2) << "\n";
        } else {
            std::cout << pairs->header << ",de00\n";
            for (const auto& r : pairs->rows) {
                std::cout << r.text
                          << fmt::format(",{:.6f}\n", pipeline::colour::ciede2000(r.lab1, r.lab2));
            }
        }
        exitCode = kExitOk;
    });
}

} // namespace replica::platform
