// Measurement CSV reading and writing.
#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>

#include <fmt/format.h>

#include <pipeline/base/input_file.h>
#include <pipeline/csv/csv_cells.h>
#include <pipeline/offline/display/measurement_set.h>

namespace replica::pipeline::display {

// No panel is this bright (the brightest HDR panels reach about 10 000 cd/m^2; a profile holds at
// most 1e5, json_schema's bound in display_profile.cpp): a larger X, Y or Z is a typo or a unit
// mistake, and one as large as 1e308 overflows the fit into a profile of NaNs.
constexpr double kMaxMeasuredCdM2 = 1e5;

Expected<void> checkMeasuredXyz(const glm::dvec3& xyz, const std::string& source, int line)
{
    if (xyz.y < -1e-3) {
        return makeError(ErrorCode::Corrupt, fmt::format("{}:{}: negative luminance Y = {} cd/m^2",
                                                         source, line, xyz.y));
    }
    for (int i = 0; i < 3; ++i) {
        if (std::abs(xyz[i]) > kMaxMeasuredCdM2) {
            return makeError(ErrorCode::Corrupt,
                             fmt::format("{}:{}: {} = {:g} cd/m^2 is beyond any display (at most "
                                         "{:g}): fix the row (a unit mistake?) or remove it",
                                         source, line, "XYZ"[i], xyz[i], kMaxMeasuredCdM2));
        }
    }
    return {};
}

Expected<MeasurementSet>
parseMeasurementCsv(const std::string& text, const std::string& source, int bitDepth)
{
    if (auto ok = checkTableLimits(text, source, ','); !ok) {
        return tl::unexpected(ok.error());
    }
    MeasurementSet set;
    set.source = source;
    bool header = false;
    double maxSeen = 0.0;
    for (const auto& [lineNo, line, cells] : csv::csvLines(text)) {
        if (!header) {
            const std::vector<std::string> want{"R", "G", "B", "X", "Y", "Z"};
            if (cells != want) {
                return makeError(ErrorCode::Corrupt,
                                 fmt::format("{}:{}: header must be R,G,B,X,Y,Z (counts, then "
                                             "XYZ in cd/m^2); found '{}'",
                                             source, lineNo, csv::shownCell(line)));
            }
            header = true;
            continue;
        }
        if (cells.size() != 6) {
            return makeError(ErrorCode::Corrupt, fmt::format("{}:{}: expected 6 values, found {}",
                                                             source, lineNo, cells.size()));
        }
        Measurement m;
        m.line = lineNo;
        for (int i = 0; i < 6; ++i) {
            double v = 0.0;
            if (!csv::parseFiniteNumber(cells[static_cast<std::size_t>(i)], v)) {
                return makeError(ErrorCode::Corrupt,
                                 fmt::format("{}:{}: '{}' in column {} is not a finite number",
                                             source, lineNo,
                                             csv::shownCell(cells[static_cast<std::size_t>(i)]),
                                             "RGBXYZ"[i]));
            }
            if (i < 3) {
                if (v < 0.0 || v != std::floor(v)) {
                    return makeError(ErrorCode::Corrupt,
                                     fmt::format("{}:{}: count {} in column {} must be a "
                                                 "non-negative integer",
                                                 source, lineNo,
                                                 csv::shownCell(cells[static_cast<std::size_t>(i)]),
                                                 "RGB"[i]));
                }
                m.counts[i] = v;
                maxSeen = std::max(maxSeen, v);
            } else {
                m.xyz[i - 3] = v;
            }
        }
        if (auto ok = checkMeasuredXyz(m.xyz, source, lineNo); !ok) {
            return tl::unexpected(ok.error());
        }
        set.rows.push_back(m);
    }
    if (!header) {
        return makeError(ErrorCode::Corrupt,
                         fmt::format("{}: no header line R,G,B,X,Y,Z (empty file?)", source));
    }
    if (set.rows.empty()) {
        return makeError(ErrorCode::Corrupt, fmt::format("{}: no measurements", source));
    }
    if (bitDepth == 0) {
        const int bits = static_cast<int>(std::ceil(std::log2(maxSeen + 1.0)));
        if (bits < 1 || bits > 16 || std::ldexp(1.0, bits) - 1.0 != maxSeen) {
            return makeError(ErrorCode::Corrupt,
                             fmt::format("{}: the largest count is {}, not 2^n - 1: the bit "
                                         "depth cannot be inferred (measure full drive, or pass "
                                         "--bits)",
                                         source, maxSeen));
        }
        bitDepth = bits;
    }
    if (bitDepth < 1 || bitDepth > 16) {
        return makeError(ErrorCode::InvalidArgument,
                         fmt::format("{}: bit depth {} is outside 1..16", source, bitDepth));
    }
    const double maxCount = std::ldexp(1.0, bitDepth) - 1.0;
    for (const auto& m : set.rows) {
        if (m.counts.x > maxCount || m.counts.y > maxCount || m.counts.z > maxCount) {
            return makeError(ErrorCode::Corrupt,
                             fmt::format("{}:{}: count above {} (the {}-bit maximum)", source,
                                         m.line, maxCount, bitDepth));
        }
    }
    set.bitDepth = bitDepth;
    return set;
}

Expected<MeasurementSet> loadMeasurementCsv(const std::filesystem::path& path, int bitDepth)
{
    auto text = readInputFile(path, kMaxCsvBytes, "measurement");
    if (!text) {
        if (text.error().code == ErrorCode::NotFound) {
            return makeError(ErrorCode::NotFound,
                             fmt::format("{}: cannot open the measurement file", path.string()));
        }
        return tl::unexpected(text.error());
    }
    return parseMeasurementCsv(*text, path.string(), bitDepth);
}

std::string measurementCsv(const std::vector<Measurement>& rows, const std::string& comment)
{
    std::string out;
    std::istringstream c(comment);
    std::string line;
    while (std::getline(c, line)) {
        out += "# " + line + "\n";
    }
    out += "R,G,B,X,Y,Z\n";
    for (const auto& m : rows) {
        out += fmt::format("{},{},{},{:.6f},{:.6f},{:.6f}\n", static_cast<long>(m.counts.x),
                           static_cast<long>(m.counts.y), static_cast<long>(m.counts.z), m.xyz.x,
                           m.xyz.y, m.xyz.z);
    }
    return out;
}

} // namespace replica::pipeline::display
