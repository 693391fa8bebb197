// ArgyllCMS CGATS reading and writing.
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
#include <pipeline/display/cgats.h>

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
                                             cell));
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

// The CGATS reader, one line at a time: the identifier, the header's keywords, the field list
// (BEGIN_DATA_FORMAT ... END_DATA_FORMAT) and the rows (BEGIN_DATA ... END_DATA).
class CgatsParser
{
public:
    enum class State { Identifier, Header, Format, Data, Done };

    explicit CgatsParser(const std::string& source) : source_(source) {}

    State state() const { return state_; }

    // One line's tokens (not empty).
    Expected<void> read(const std::vector<std::string>& tok, const std::string& text, int lineNo)
    {
        switch (state_) {
        case State::Identifier:
            return identifier(tok, text, lineNo);
        case State::Header:
            return header(tok, lineNo);
        case State::Format:
            return format(tok);
        case State::Data:
            return data(tok, lineNo);
        case State::Done:
            break;
        }
        return {};
    }

    // The table, or what the file lacks where it ends early.
    Expected<CgatsTable> finish()
    {
        const std::string& source = source_;
        if (state_ == State::Identifier) {
            return makeError(ErrorCode::Corrupt, fmt::format("{}: empty file", source));
        }
        if (state_ == State::Header) {
            return makeError(ErrorCode::Corrupt,
                             fmt::format("{}: no BEGIN_DATA: no readings", source));
        }
        if (state_ == State::Format) {
            return makeError(ErrorCode::Corrupt,
                             fmt::format("{}:{}: BEGIN_DATA_FORMAT without END_DATA_FORMAT", source,
                                         formatLine_));
        }
        if (state_ == State::Data) {
            return makeError(
                    ErrorCode::Corrupt,
                    fmt::format("{}:{}: BEGIN_DATA without END_DATA (the file is cut short)",
                                source, dataLine_));
        }
        return std::move(table_);
    }

private:
    Expected<void>
    identifier(const std::vector<std::string>& tok, const std::string& line, int lineNo)
    {
        const std::string& source = source_;
        if (tok.size() != 1 || tok[0].size() < 3 ||
            !std::all_of(tok[0].begin(), tok[0].end(), [](unsigned char ch) {
                return std::isupper(ch) != 0 || std::isdigit(ch) != 0;
            })) {
            return makeError(ErrorCode::Corrupt,
                             fmt::format("{}:{}: not a CGATS file: the first line must be "
                                         "its type (CTI1, CTI3), found '{}'",
                                         source, lineNo, csv::trimCell(line)));
        }
        table_.identifier = tok[0];
        state_ = State::Header;
        return {};
    }

    Expected<void> header(const std::vector<std::string>& tok, int lineNo)
    {
        const std::string& source = source_;
        if (tok[0] == "BEGIN_DATA_FORMAT") {
            state_ = State::Format;
            formatLine_ = lineNo;
        } else if (tok[0] == "BEGIN_DATA") {
            if (table_.fields.empty()) {
                return makeError(ErrorCode::Corrupt,
                                 fmt::format("{}:{}: BEGIN_DATA before the field list "
                                             "(BEGIN_DATA_FORMAT ... END_DATA_FORMAT)",
                                             source, lineNo));
            }
            state_ = State::Data;
            dataLine_ = lineNo;
        } else if (tok[0] == "NUMBER_OF_FIELDS" || tok[0] == "NUMBER_OF_SETS") {
            double v = 0.0;
            if (tok.size() != 2 || !parseNumber(tok[1], v) || v < 0 || v != std::floor(v)) {
                return makeError(ErrorCode::Corrupt, fmt::format("{}:{}: {} needs a whole number",
                                                                 source, lineNo, tok[0]));
            }
            (tok[0] == "NUMBER_OF_FIELDS" ? declaredFields_ : declaredSets_) = static_cast<long>(v);
        } else if (tok[0] == "KEYWORD") {
            // Declares a private keyword; its value follows on its own line.
        } else if (tok.size() >= 2) {
            std::string value = tok[1];
            for (std::size_t i = 2; i < tok.size(); ++i) {
                value += " " + tok[i];
            }
            table_.keywords.emplace_back(tok[0], value);
        } else {
            table_.keywords.emplace_back(tok[0], "");
        }
        return {};
    }

    Expected<void> format(const std::vector<std::string>& tok)
    {
        const std::string& source = source_;
        if (tok[0] == "END_DATA_FORMAT") {
            if (declaredFields_ >= 0 &&
                static_cast<long>(table_.fields.size()) != declaredFields_) {
                return makeError(ErrorCode::Corrupt,
                                 fmt::format("{}:{}: NUMBER_OF_FIELDS is {} but the format "
                                             "lists {} fields",
                                             source, formatLine_, declaredFields_,
                                             table_.fields.size()));
            }
            state_ = State::Header;
        } else {
            table_.fields.insert(table_.fields.end(), tok.begin(), tok.end());
        }
        return {};
    }

    Expected<void> data(const std::vector<std::string>& tok, int lineNo)
    {
        const std::string& source = source_;
        if (tok[0] == "END_DATA") {
            if (!pending_.empty()) {
                return makeError(ErrorCode::Corrupt,
                                 fmt::format("{}:{}: the last row has {} values, expected {}",
                                             source, pendingLine_, pending_.size(),
                                             table_.fields.size()));
            }
            if (declaredSets_ >= 0 && static_cast<long>(table_.rows.size()) != declaredSets_) {
                return makeError(ErrorCode::Corrupt,
                                 fmt::format("{}:{}: NUMBER_OF_SETS is {} but the data has "
                                             "{} rows",
                                             source, lineNo, declaredSets_, table_.rows.size()));
            }
            state_ = State::Done;
            return {};
        }
        // Argyll writes a row a line; a row that does not fill its line is an error there.
        if (pending_.empty()) {
            pendingLine_ = lineNo;
        }
        pending_.insert(pending_.end(), tok.begin(), tok.end());
        if (pending_.size() == table_.fields.size()) {
            table_.rows.push_back(pending_);
            table_.rowLines.push_back(pendingLine_);
            pending_.clear();
        } else {
            return makeError(ErrorCode::Corrupt,
                             fmt::format("{}:{}: {} values, expected {} ({})", source, pendingLine_,
                                         pending_.size(), table_.fields.size(),
                                         fmt::join(table_.fields, " ")));
        }
        return {};
    }

    const std::string& source_;
    CgatsTable table_;
    State state_ = State::Identifier;
    long declaredFields_ = -1;
    long declaredSets_ = -1;
    int formatLine_ = 0;
    int dataLine_ = 0;
    std::vector<std::string> pending_; // data tokens of the row being read
    int pendingLine_ = 0;
};

} // namespace

Expected<CgatsTable> parseCgats(const std::string& text, const std::string& source)
{
    if (auto ok = checkTableLimits(text, source, ' '); !ok) {
        return tl::unexpected(ok.error());
    }
    CgatsParser parser(source);
    std::istringstream in(text);
    std::string line;
    int lineNo = 0;
    std::vector<std::string> tok;
    while (parser.state() != CgatsParser::State::Done && std::getline(in, line)) {
        ++lineNo;
        if (!tokenize(line, tok)) {
            return makeError(ErrorCode::Corrupt,
                             fmt::format("{}:{}: unterminated quoted string", source, lineNo));
        }
        if (tok.empty()) {
            continue;
        }
        if (auto ok = parser.read(tok, line, lineNo); !ok) {
            return tl::unexpected(ok.error());
        }
    }
    return parser.finish();
}

std::string cgatsText(const CgatsTable& t)
{
    static const std::vector<std::string> standard{"DESCRIPTOR", "ORIGINATOR", "CREATED"};
    std::string out = t.identifier + "\n\n";
    for (const auto& [k, v] : t.keywords) {
        if (std::find(standard.begin(), standard.end(), k) == standard.end()) {
            out += fmt::format("KEYWORD \"{}\"\n", k);
        }
        out += fmt::format("{} \"{}\"\n", k, v);
    }
    out += fmt::format("\nNUMBER_OF_FIELDS {}\nBEGIN_DATA_FORMAT\n{}\nEND_DATA_FORMAT\n\n",
                       t.fields.size(), fmt::join(t.fields, " "));
    out += fmt::format("NUMBER_OF_SETS {}\nBEGIN_DATA\n", t.rows.size());
    for (const auto& r : t.rows) {
        out += fmt::format("{}\n", fmt::join(r, " "));
    }
    out += "END_DATA\n";
    return out;
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
                                     source, *rep));
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
                                             m.line, t->fields[col], t->rows[r][col]));
            }
            m.xyz[k] = v * scale;
        }
        if (m.xyz.y < -1e-3) {
            return makeError(ErrorCode::Corrupt,
                             fmt::format("{}:{}: negative luminance Y = {} cd/m^2", source, m.line,
                                         m.xyz.y));
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
        return makeError(
                ErrorCode::Corrupt,
                fmt::format("{}: COLOR_REP is '{}', a display patch set is RGB", source, *rep));
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
