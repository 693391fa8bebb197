// ArgyllCMS CGATS reading and writing: the tables through Little CMS 2's IT8 functions
// (cgats_it8.cpp); Argyll's row layout and the lines for messages checked here first.
#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <fstream>
#include <sstream>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <pipeline/base/input_file.h>
#include <pipeline/csv/csv_cells.h>
#include <pipeline/offline/display/cgats.h>
#include <pipeline/offline/display/cgats_it8.h>

namespace replica::pipeline::display {
namespace {

// Whitespace-separated tokens of a line; "quoted strings" are one token without their quotes.
// A '#' outside quotes starts a comment. False on an unterminated quote.
bool tokenize(const std::string& line, std::vector<std::string>& out)
{
    out.clear();
    std::size_t i = 0;
    while (i < line.size()) {
        const char c = line[i];
        if (c == ' ' || c == '\t' || c == '\r') {
            ++i;
        } else if (c == '#') {
            break;
        } else if (c == '"') {
            const std::size_t end = line.find('"', i + 1);
            if (end == std::string::npos) {
                return false;
            }
            out.push_back(line.substr(i + 1, end - i - 1));
            i = end + 1;
        } else {
            std::size_t end = i;
            while (end < line.size() && line[end] != ' ' && line[end] != '\t' &&
                   line[end] != '\r') {
                ++end;
            }
            out.push_back(line.substr(i, end - i));
            i = end;
        }
    }
    return true;
}

bool parseNumber(const std::string& s, double& v)
{
    return csv::parseFiniteNumber(s, v);
}

std::string nowText()
{
    const std::time_t t = std::time(nullptr);
    char buf[64];
    std::tm tmv{};
    gmtime_r(&t, &tmv);
    std::strftime(buf, sizeof buf, "%a %b %d %H:%M:%S %Y", &tmv);
    return buf;
}

// RGB columns of a table: counts at bitDepth, rounded.
Expected<std::vector<glm::dvec3>>
countsOf(const CgatsTable& t, const std::string& source, int bitDepth)
{
    if (bitDepth < 1 || bitDepth > 16) {
        return makeError(ErrorCode::InvalidArgument,
                         fmt::format("{}: bit depth {} is outside 1..16", source, bitDepth));
    }
    std::array<int, 3> col{t.field("RGB_R"), t.field("RGB_G"), t.field("RGB_B")};
    for (int c = 0; c < 3; ++c) {
        if (col[static_cast<std::size_t>(c)] < 0) {
            return makeError(ErrorCode::Corrupt,
                             fmt::format("{}: no {} field (a display patch set needs RGB_R, "
                                         "RGB_G and RGB_B in 0-100)",
                                         source, std::array{"RGB_R", "RGB_G", "RGB_B"}[c]));
        }
    }
    const double maxCount = std::ldexp(1.0, bitDepth) - 1.0;
    std::vector<glm::dvec3> out;
    for (std::size_t r = 0; r < t.rows.size(); ++r) {
        glm::dvec3 counts;
        for (int c = 0; c < 3; ++c) {
            const auto& cell =
                    t.rows[r][static_cast<std::size_t>(col[static_cast<std::size_t>(c)])];
            double v = 0.0;
            if (!parseNumber(cell, v) || v < 0.0 || v > 100.0) {
                return makeError(ErrorCode::Corrupt,
                                 fmt::format("{}:{}: {} '{}' is not a number in 0-100", source,
                                             t.rowLines[r],
                                             t.fields[static_cast<std::size_t>(
                                                     col[static_cast<std::size_t>(c)])],
                                             csv::shownCell(cell)));
            }
            counts[c] = std::round(v / 100.0 * maxCount);
        }
        out.push_back(counts);
    }
    return out;
}

} // namespace

const std::string* CgatsTable::keyword(const std::string& name) const
{
    for (const auto& [k, v] : keywords) {
        if (k == name) {
            return &v;
        }
    }
    return nullptr;
}

int CgatsTable::field(const std::string& name) const
{
    const auto it = std::find(fields.begin(), fields.end(), name);
    return it == fields.end() ? -1 : static_cast<int>(it - fields.begin());
}

namespace {

bool isIdentifier(const std::vector<std::string>& tok)
{
    return tok.size() == 1 && tok[0].size() >= 3 &&
           std::all_of(tok[0].begin(), tok[0].end(), [](unsigned char ch) {
               return std::isupper(ch) != 0 || std::isdigit(ch) != 0;
           });
}

// What lcms2's IT8 reader leaves to its caller, from the text of the first table: the line of each
// data row (for messages) and the checks lcms2 does not make, or makes without the line a person
// needs: a first line that is a type, quotes closed (lcms2 runs an open one to the line's end),
// the field list closed and as long as NUMBER_OF_FIELDS says, END_DATA present (lcms2 takes a file
// cut short inside its data), one row a line with every field, as Argyll writes them (lcms2 lets a
// short row take the next line's values), NUMBER_OF_SETS rows, and no .INCLUDE (lcms2 follows it).
struct Layout {
    std::vector<std::string> fields;
    std::vector<int> rowLines;
};

class LayoutScan
{
public:
    explicit LayoutScan(const std::string& source) : source_(source) {}

    // One line's tokens (not empty); true once the first table's END_DATA is read.
    Expected<bool> line(const std::vector<std::string>& tok, const std::string& text, int lineNo)
    {
        if (at_ == At::Identifier) {
            if (!isIdentifier(tok)) {
                return fail(lineNo, fmt::format("not a CGATS file: the first line must be its type "
                                                "(CTI1, CTI3), found '{}'",
                                                csv::shownCell(csv::trimCell(text))));
            }
            at_ = At::Header;
        } else if (at_ == At::Header) {
            return header(tok, lineNo);
        } else if (at_ == At::Format) {
            if (tok[0] != "END_DATA_FORMAT") {
                layout_.fields.insert(layout_.fields.end(), tok.begin(), tok.end());
            } else if (fields_ >= 0 && static_cast<long>(layout_.fields.size()) != fields_) {
                return fail(formatLine_, fmt::format("NUMBER_OF_FIELDS is {} but the format "
                                                     "lists {} fields",
                                                     fields_, layout_.fields.size()));
            } else {
                at_ = At::Header;
            }
        } else if (tok[0] == "END_DATA") {
            if (sets_ >= 0 && static_cast<long>(layout_.rowLines.size()) != sets_) {
                return fail(lineNo, fmt::format("NUMBER_OF_SETS is {} but the data has {} rows",
                                                sets_, layout_.rowLines.size()));
            }
            return true;
        } else if (tok.size() != layout_.fields.size()) {
            return fail(lineNo, fmt::format("{} values, expected {} ({})", tok.size(),
                                            layout_.fields.size(), fmt::join(layout_.fields, " ")));
        } else {
            layout_.rowLines.push_back(lineNo);
        }
        return false;
    }

    // The layout once END_DATA was read, or what the file lacks where it ends early.
    Expected<Layout> finish(bool done) const
    {
        if (done) {
            return layout_;
        }
        switch (at_) {
        case At::Identifier:
            return fail(0, "empty file");
        case At::Header:
            return fail(0, "no BEGIN_DATA: no readings");
        case At::Format:
            return fail(formatLine_, "BEGIN_DATA_FORMAT without END_DATA_FORMAT");
        case At::Data:
            break;
        }
        return fail(dataLine_, "BEGIN_DATA without END_DATA (the file is cut short)");
    }

private:
    enum class At { Identifier, Header, Format, Data };

    Expected<bool> header(const std::vector<std::string>& tok, int lineNo)
    {
        if (tok[0] == "BEGIN_DATA_FORMAT") {
            at_ = At::Format;
            formatLine_ = lineNo;
        } else if (tok[0] == "BEGIN_DATA") {
            if (layout_.fields.empty()) {
                return fail(lineNo, "BEGIN_DATA before the field list (BEGIN_DATA_FORMAT ... "
                                    "END_DATA_FORMAT)");
            }
            at_ = At::Data;
            dataLine_ = lineNo;
        } else if (tok[0] == "NUMBER_OF_FIELDS" || tok[0] == "NUMBER_OF_SETS") {
            double v = 0.0;
            if (tok.size() != 2 || !parseNumber(tok[1], v) || v < 0 || v != std::floor(v)) {
                return fail(lineNo, fmt::format("{} needs a whole number", tok[0]));
            }
            (tok[0] == "NUMBER_OF_FIELDS" ? fields_ : sets_) = static_cast<long>(v);
        }
        return false;
    }

    tl::unexpected<Error> fail(int lineNo, const std::string& what) const
    {
        return makeError(ErrorCode::Corrupt,
                         lineNo > 0 ? fmt::format("{}:{}: {}", source_, lineNo, what)
                                    : fmt::format("{}: {}", source_, what));
    }

    const std::string& source_;
    Layout layout_;
    At at_ = At::Identifier;
    long fields_ = -1;
    long sets_ = -1;
    int formatLine_ = 0;
    int dataLine_ = 0;
};

bool isInclude(const std::string& token)
{
    return token.size() == 8 && token[0] == '.' &&
           std::equal(token.begin() + 1, token.end(), "INCLUDE", [](char a, char b) {
               return std::toupper(static_cast<unsigned char>(a)) == b;
           });
}

Expected<Layout> scanLayout(const std::string& text, const std::string& source)
{
    LayoutScan scan(source);
    std::istringstream in(text);
    std::string line;
    std::vector<std::string> tok;
    bool done = false;
    for (int lineNo = 1; std::getline(in, line); ++lineNo) {
        const bool closed = tokenize(line, tok);
        if (std::any_of(tok.begin(), tok.end(), isInclude)) {
            // lcms2 would open the file it names, in any table: a measurement file stands alone.
            return makeError(ErrorCode::Corrupt,
                             fmt::format("{}:{}: .INCLUDE is not followed: give the readings "
                                         "in one file",
                                         source, lineNo));
        }
        if (done) {
            continue;
        }
        if (!closed) {
            return makeError(ErrorCode::Corrupt,
                             fmt::format("{}:{}: unterminated quoted string", source, lineNo));
        }
        if (tok.empty()) {
            continue;
        }
        auto end = scan.line(tok, line, lineNo);
        if (!end) {
            return tl::unexpected(end.error());
        }
        done = *end;
    }
    return scan.finish(done);
}

} // namespace

Expected<CgatsTable> parseCgats(const std::string& text, const std::string& source)
{
    if (auto ok = checkTableLimits(text, source, ' '); !ok) {
        return tl::unexpected(ok.error());
    }
    auto layout = scanLayout(text, source);
    if (!layout) {
        return tl::unexpected(layout.error());
    }
    return readIt8Table(text, source, layout->fields.size(), layout->rowLines);
}

std::string cgatsText(const CgatsTable& t)
{
    return writeIt8Table(t);
}

namespace {

// The factor from a .ti3's XYZ to cd/m^2: 1 for NORMALIZED_TO_Y_100 "NO", else white's luminance
// (whiteCdM2, or LUMINANCE_XYZ_CDM2's Y) / 100.
Expected<double> ti3Scale(const CgatsTable& t, const std::string& source, double whiteCdM2)
{
    const auto* normed = t.keyword("NORMALIZED_TO_Y_100");
    if (normed != nullptr && *normed == "NO") {
        return 1.0;
    }
    if (whiteCdM2 > 0.0 && std::isfinite(whiteCdM2)) {
        return whiteCdM2 / 100.0;
    }
    const auto* lum = t.keyword("LUMINANCE_XYZ_CDM2");
    double x = 0.0;
    double y = 0.0;
    double z = 0.0;
    if (lum == nullptr || std::sscanf(lum->c_str(), " %lf %lf %lf", &x, &y, &z) != 3 ||
        !(y > 0.0) || !std::isfinite(y)) {
        return makeError(ErrorCode::Corrupt,
                         fmt::format("{}: XYZ normalised to white Y = 100 and no usable "
                                     "LUMINANCE_XYZ_CDM2 \"X Y Z\": the absolute luminance is "
                                     "unknown; give white's luminance in cd/m^2 (display fit "
                                     "--white-cdm2 VALUE, e.g. spotread's reading of full white), "
                                     "or measure with dispread, which writes it (or set "
                                     "NORMALIZED_TO_Y_100 \"NO\" for readings in cd/m^2)",
                                     source));
    }
    return y / 100.0;
}

} // namespace

Expected<MeasurementSet>
parseTi3(const std::string& text, const std::string& source, int bitDepth, double whiteCdM2)
{
    auto t = parseCgats(text, source);
    if (!t) {
        return tl::unexpected(t.error());
    }
    std::array<int, 3> xyzCol{t->field("XYZ_X"), t->field("XYZ_Y"), t->field("XYZ_Z")};
    if (xyzCol[0] < 0 || xyzCol[1] < 0 || xyzCol[2] < 0) {
        return makeError(ErrorCode::Corrupt,
                         fmt::format("{}: no XYZ_X, XYZ_Y and XYZ_Z fields: not readings (a "
                                     ".ti1 patch set is measured first)",
                                     source));
    }
    if (const auto* rep = t->keyword("COLOR_REP"); rep != nullptr && *rep != "RGB_XYZ") {
        return makeError(ErrorCode::Corrupt,
                         fmt::format("{}: COLOR_REP is '{}', a display's readings are RGB_XYZ",
                                     source, csv::shownCell(*rep)));
    }
    // Display readings are normalised to white Y = 100 unless the file says NO (Argyll's rule).
    auto scaleOr = ti3Scale(*t, source, whiteCdM2);
    if (!scaleOr) {
        return tl::unexpected(scaleOr.error());
    }
    const double scale = *scaleOr;
    auto counts = countsOf(*t, source, bitDepth);
    if (!counts) {
        return tl::unexpected(counts.error());
    }
    MeasurementSet set;
    set.source = source;
    set.bitDepth = bitDepth;
    for (std::size_t r = 0; r < t->rows.size(); ++r) {
        Measurement m;
        m.counts = (*counts)[r];
        m.line = t->rowLines[r];
        for (int k = 0; k < 3; ++k) {
            const auto col = static_cast<std::size_t>(xyzCol[static_cast<std::size_t>(k)]);
            double v = 0.0;
            if (!parseNumber(t->rows[r][col], v)) {
                return makeError(ErrorCode::Corrupt,
                                 fmt::format("{}:{}: {} '{}' is not a finite number", source,
                                             m.line, csv::shownCell(t->fields[col]),
                                             csv::shownCell(t->rows[r][col])));
            }
            m.xyz[k] = v * scale;
        }
        if (auto ok = checkMeasuredXyz(m.xyz, source, m.line); !ok) {
            return tl::unexpected(ok.error());
        }
        set.rows.push_back(m);
    }
    if (set.rows.empty()) {
        return makeError(ErrorCode::Corrupt, fmt::format("{}: no readings", source));
    }
    return set;
}

std::string
ti3Text(const std::vector<Measurement>& rows, int bitDepth, const std::string& originator)
{
    const double maxCount = std::ldexp(1.0, bitDepth) - 1.0;
    glm::dvec3 white(0.0);
    for (const auto& m : rows) {
        if (m.xyz.y > white.y) {
            white = m.xyz;
        }
    }
    const double scale = white.y > 0.0 ? 100.0 / white.y : 1.0;
    CgatsTable t;
    t.identifier = "CTI3";
    t.keywords = {
            {"DESCRIPTOR", "Argyll Calibration Target chart information 3"},
            {"ORIGINATOR", originator},
            {"CREATED", nowText()},
            {"DEVICE_CLASS", "DISPLAY"},
            {"COLOR_REP", "RGB_XYZ"},
            {"LUMINANCE_XYZ_CDM2", fmt::format("{:.6f} {:.6f} {:.6f}", white.x, white.y, white.z)},
            {"NORMALIZED_TO_Y_100", white.y > 0.0 ? "YES" : "NO"}};
    t.fields = {"SAMPLE_ID", "RGB_R", "RGB_G", "RGB_B", "XYZ_X", "XYZ_Y", "XYZ_Z"};
    for (std::size_t i = 0; i < rows.size(); ++i) {
        const auto& m = rows[i];
        const glm::dvec3 rgb = m.counts / maxCount * 100.0;
        const glm::dvec3 xyz = m.xyz * scale;
        t.rows.push_back({std::to_string(i + 1), fmt::format("{:.6f}", rgb.x),
                          fmt::format("{:.6f}", rgb.y), fmt::format("{:.6f}", rgb.z),
                          fmt::format("{:.8g}", xyz.x), fmt::format("{:.8g}", xyz.y),
                          fmt::format("{:.8g}", xyz.z)});
    }
    return cgatsText(t);
}

Expected<std::vector<glm::dvec3>>
parseTi1(const std::string& text, const std::string& source, int bitDepth)
{
    auto t = parseCgats(text, source);
    if (!t) {
        return tl::unexpected(t.error());
    }
    if (const auto* rep = t->keyword("COLOR_REP"); rep != nullptr && rep->rfind("RGB", 0) != 0) {
        return makeError(ErrorCode::Corrupt,
                         fmt::format("{}: COLOR_REP is '{}', a display patch set is RGB", source,
                                     csv::shownCell(*rep)));
    }
    auto counts = countsOf(*t, source, bitDepth);
    if (counts && counts->empty()) {
        return makeError(ErrorCode::Corrupt, fmt::format("{}: no patches", source));
    }
    return counts;
}

std::string
ti1Text(const std::vector<glm::dvec3>& counts, int bitDepth, const std::string& originator)
{
    const double maxCount = std::ldexp(1.0, bitDepth) - 1.0;
    CgatsTable t;
    t.identifier = "CTI1";
    t.keywords = {{"DESCRIPTOR", "Argyll Calibration Target chart information 1"},
                  {"ORIGINATOR", originator},
                  {"CREATED", nowText()},
                  {"COLOR_REP", "RGB"}};
    t.fields = {"SAMPLE_ID", "RGB_R", "RGB_G", "RGB_B"};
    for (std::size_t i = 0; i < counts.size(); ++i) {
        const glm::dvec3 rgb = counts[i] / maxCount * 100.0;
        t.rows.push_back({std::to_string(i + 1), fmt::format("{:.6f}", rgb.x),
                          fmt::format("{:.6f}", rgb.y), fmt::format("{:.6f}", rgb.z)});
    }
    return cgatsText(t);
}

bool isTi3Path(const std::filesystem::path& path)
{
    auto ext = path.extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(),
                   [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    return ext == ".ti3";
}

Expected<MeasurementSet>
loadMeasurements(const std::filesystem::path& path, int bitDepth, double whiteCdM2)
{
    if (!isTi3Path(path)) {
        if (whiteCdM2 > 0.0) {
            return makeError(ErrorCode::InvalidArgument,
                             fmt::format("{}: white's luminance is for a .ti3 normalised to "
                                         "white Y = 100; a CSV's XYZ are cd/m^2 already",
                                         path.string()));
        }
        return loadMeasurementCsv(path, bitDepth);
    }
    auto text = readInputFile(path, kMaxCsvBytes, "measurement");
    if (!text) {
        if (text.error().code == ErrorCode::NotFound) {
            return makeError(ErrorCode::NotFound,
                             fmt::format("{}: cannot open the measurement file", path.string()));
        }
        return tl::unexpected(text.error());
    }
    return parseTi3(*text, path.string(), bitDepth == 0 ? 8 : bitDepth, whiteCdM2);
}

} // namespace replica::pipeline::display
