// Viewing-angle measurement CSV.
#include <cmath>
#include <fstream>
#include <sstream>
#include <vector>

#include <fmt/format.h>

#include <pipeline/base/input_file.h>
#include <pipeline/csv/csv_cells.h>
#include <pipeline/offline/display/viewing_angle_csv.h>

namespace replica::pipeline::display {

Expected<ViewingAngleTable> parseViewingAngleCsv(const std::string& text, const std::string& source)
{
    if (auto ok = checkTableLimits(text, source, ','); !ok) {
        return tl::unexpected(ok.error());
    }
    ViewingAngleTable t;
    bool header = false;
    double x0 = 0.0;
    double y0 = 0.0;
    double lum0 = 0.0;
    for (const auto& [lineNo, line, cells] : csv::csvLines(text)) {
        if (!header) {
            if (cells != std::vector<std::string>{"angle_deg", "X", "Y", "Z"}) {
                return makeError(ErrorCode::Corrupt,
                                 fmt::format("{}:{}: header must be angle_deg,X,Y,Z (full white "
                                             "measured off axis, cd/m^2); found '{}'",
                                             source, lineNo, csv::shownCell(line)));
            }
            header = true;
            continue;
        }
        double v[4] = {};
        if (cells.size() != 4) {
            return makeError(ErrorCode::Corrupt, fmt::format("{}:{}: expected 4 values, found {}",
                                                             source, lineNo, cells.size()));
        }
        for (std::size_t i = 0; i < 4; ++i) {
            if (!csv::parseFiniteNumber(cells[i], v[i])) {
                return makeError(ErrorCode::Corrupt,
                                 fmt::format("{}:{}: '{}' is not a finite number", source, lineNo,
                                             csv::shownCell(cells[i])));
            }
        }
        const double sum = v[1] + v[2] + v[3];
        if (!(v[2] > 0.0) || !(sum > 0.0)) {
            return makeError(ErrorCode::Corrupt,
                             fmt::format("{}:{}: white must have Y > 0 at every angle (the panel "
                                         "was not lit, or the meter missed it)",
                                         source, lineNo));
        }
        const double x = v[1] / sum;
        const double y = v[2] / sum;
        if (t.angleDeg.empty()) {
            if (v[0] != 0.0) {
                return makeError(ErrorCode::Corrupt,
                                 fmt::format("{}:{}: the first row must be on axis (angle_deg 0)",
                                             source, lineNo));
            }
            x0 = x;
            y0 = y;
            lum0 = v[2];
        }
        t.angleDeg.push_back(v[0]);
        t.luminanceRatio.push_back(v[2] / lum0);
        t.dx.push_back(x - x0);
        t.dy.push_back(y - y0);
    }
    if (!header || t.angleDeg.empty()) {
        return makeError(ErrorCode::Corrupt,
                         fmt::format("{}: no measurements (header angle_deg,X,Y,Z, then one row "
                                     "per angle)",
                                     source));
    }
    if (auto ok = t.validate(); !ok) {
        return makeError(ErrorCode::Corrupt, fmt::format("{}: {}", source, ok.error().message));
    }
    return t;
}

Expected<ViewingAngleTable> loadViewingAngleCsv(const std::filesystem::path& path)
{
    auto text = readInputFile(path, kMaxCsvBytes, "viewing-angle table");
    if (!text) {
        if (text.error().code == ErrorCode::NotFound) {
            return makeError(ErrorCode::NotFound,
                             fmt::format("{}: cannot open the viewing-angle table", path.string()));
        }
        return tl::unexpected(text.error());
    }
    return parseViewingAngleCsv(*text, path.string());
}

} // namespace replica::pipeline::display
