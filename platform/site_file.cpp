// Site file sections: text replacement checked with toml++.
#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <optional>
#include <sstream>
#include <vector>

#include <fmt/format.h>
#include <toml++/toml.h>

#include <pipeline/base/input_file.h>
#include <pipeline/base/output_file.h>
#include <platform/site_config.h>
#include <platform/site_file.h>
#include <recordings/device_kind.h>

namespace replica::platform {
namespace {

Expected<std::string> readText(const std::filesystem::path& file)
{
    return readInputFile(file, kMaxTomlBytes, "site");
}

Expected<toml::table> parse(const std::string& text, const std::filesystem::path& file)
{
    try {
        return toml::parse(text, file.string());
    } catch (const toml::parse_error& e) {
        return makeError(ErrorCode::Corrupt,
                         fmt::format("{}:{}: not valid TOML: {}; fix or move the file and run the "
                                     "calibration again",
                                     file.string(), e.source().begin.line, e.description()));
    }
}

std::string trim(const std::string& s)
{
    const auto a = s.find_first_not_of(" \t\r");
    const auto b = s.find_last_not_of(" \t\r");
    return a == std::string::npos ? std::string() : s.substr(a, b - a + 1);
}

std::string today()
{
    const std::time_t t = std::time(nullptr);
    std::tm tm{};
    gmtime_r(&t, &tm);
    char buf[32];
    std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%SZ", &tm);
    return buf;
}

std::vector<std::string> splitLines(const std::string& text)
{
    std::vector<std::string> lines;
    std::size_t start = 0;
    while (start < text.size()) {
        const auto nl = text.find('\n', start);
        if (nl == std::string::npos) {
            lines.push_back(text.substr(start));
            break;
        }
        lines.push_back(text.substr(start, nl - start));
        start = nl + 1;
    }
    return lines;
}

// Marks the lines that continue a multi-line value (an array, a string), whose text may look like
// a table header: only the lines left unmarked can open a section.
void markValueLines(const toml::node& node, std::vector<bool>& inValue)
{
    if (const auto* t = node.as_table(); t != nullptr && !t->is_inline()) {
        for (auto&& [k, v] : *t) {
            markValueLines(v, inValue);
        }
        return;
    }
    if (const auto* a = node.as_array(); a != nullptr && !a->empty() && a->front().is_table() &&
                                         !a->front().as_table()->is_inline()) {
        for (auto&& v : *a) { // [[array.of.tables]]: headers, each with its own keys
            markValueLines(v, inValue);
        }
        return;
    }
    const auto& s = node.source();
    for (auto l = s.begin.line + 1; l <= s.end.line && l <= inValue.size(); ++l) {
        inValue[l - 1] = true;
    }
}

// "[ tracker ]  # comment" -> "[tracker]": a header line as its table's name.
std::string headerName(const std::string& line)
{
    std::string name;
    for (const char c : line.substr(0, line.find('#'))) {
        if (c != ' ' && c != '\t' && c != '\r') {
            name += c;
        }
    }
    return name;
}

// The comment lines a calibration writes above its keys, from an earlier run (replaced with the
// keys, so that they do not pile up): "# 'replica calibrate tracker' on ...", or the same text as
// one of the new section's comments.
bool isCalibrationComment(const std::string& line, const std::vector<std::string>& bodyLines)
{
    const std::string t = trim(line);
    if (t.rfind("# 'replica calibrate ", 0) == 0 ||
        t.rfind("# direct-sensor level from ", 0) == 0) {
        return true;
    }
    return t.rfind('#', 0) == 0 &&
           std::find(bodyLines.begin(), bodyLines.end(), t) != bodyLines.end();
}

// The first line of [section]'s block and the one after its last (0-based), or nullopt when the
// file has no [section] header.
std::optional<std::pair<std::size_t, std::size_t>> sectionBlock(
        const std::vector<std::string>& lines, const toml::table& table, const std::string& section)
{
    std::vector<bool> inValue(lines.size(), false);
    markValueLines(table, inValue);
    std::optional<std::size_t> first;
    for (std::size_t i = 0; i < lines.size(); ++i) {
        if (inValue[i] || trim(lines[i]).rfind('[', 0) != 0) {
            continue;
        }
        if (first) {
            return std::make_pair(*first, i);
        }
        if (headerName(lines[i]) == "[" + section + "]") {
            first = i;
        }
    }
    return first ? std::optional(std::make_pair(*first, lines.size())) : std::nullopt;
}

// The file with [section]'s keys that 'body' sets replaced by it: each old key's lines (and the
// comments an earlier calibration wrote above it) dropped, the new lines where the first of them
// was, or at the end of the section. Every other line stays byte for byte: the site's other
// settings (the tracker's port and bind address) and the technician's comments.
Expected<std::string> replaceSiteKeys(const std::string& old,
                                      const toml::table& table,
                                      const std::filesystem::path& file,
                                      const std::string& section,
                                      const std::string& body)
{
    const std::vector<std::string> lines = splitLines(old);
    const auto block = sectionBlock(lines, table, section);
    if (!block) {
        std::string kept = old;
        if (!kept.empty() && kept.back() != '\n') {
            kept += '\n';
        }
        return kept + (kept.empty() ? "" : "\n") + "[" + section + "]\n" + body;
    }
    std::vector<std::string> bodyLines;
    for (const auto& l : splitLines(body)) {
        bodyLines.push_back(trim(l));
    }
    const auto* sec = table[section].as_table();
    auto newKeys = parse(body, "(the new [" + section + "])");
    if (!newKeys || sec == nullptr) {
        return newKeys ? makeError(ErrorCode::InvalidArgument,
                                   fmt::format("{}: [{}] is not a table", file.string(), section))
                       : tl::unexpected(newKeys.error());
    }
    std::vector<bool> drop(lines.size(), false);
    std::size_t insertAt = block->second;
    while (insertAt > block->first + 1 && trim(lines[insertAt - 1]).empty()) {
        --insertAt; // after the section's last line, before the blank lines that end it
    }
    std::size_t firstDropped = lines.size();
    for (auto&& [key, value] : *newKeys) {
        const auto it = sec->find(key.str());
        if (it == sec->end()) {
            continue;
        }
        const std::size_t from = it->first.source().begin.line;
        const std::size_t to = it->second.source().end.line;
        const auto* sub = it->second.as_table();
        if ((sub != nullptr && !sub->is_inline()) || from <= block->first + 1 ||
            to > block->second) {
            return makeError(
                    ErrorCode::InvalidArgument,
                    fmt::format("{}:{}: {}.{} is not one 'key = value' under [{}]; make it "
                                "one (or remove it) and run the calibration again",
                                file.string(), from, section, key.str(), section));
        }
        std::size_t top = from - 1;
        while (top > block->first + 1 && isCalibrationComment(lines[top - 1], bodyLines)) {
            --top;
        }
        std::fill(drop.begin() + static_cast<std::ptrdiff_t>(top),
                  drop.begin() + static_cast<std::ptrdiff_t>(to), true);
        firstDropped = std::min(firstDropped, top);
    }
    if (firstDropped < lines.size()) {
        insertAt = firstDropped;
    }
    const bool finalNewline = old.back() == '\n';
    std::string out;
    for (std::size_t i = 0; i <= lines.size(); ++i) {
        if (i == insertAt) {
            out += body;
        }
        if (i < lines.size() && !drop[i]) {
            out += lines[i] +
                   (i + 1 < lines.size() || finalNewline || insertAt == lines.size() ? "\n" : "");
        }
    }
    return out;
}

} // namespace

Expected<void> writeSiteSection(const std::filesystem::path& file,
                                const std::string& section,
                                const std::string& body)
{
    // The site file goes where the package installed it (/etc/replica): a folder that is not
    // there is a mistyped --site, never one to create.
    const std::filesystem::path folder = file.has_parent_path() ? file.parent_path() : ".";
    std::error_code ec;
    if (!std::filesystem::is_directory(folder, ec)) {
        return makeError(ErrorCode::NotFound,
                         fmt::format("{}: there is no folder {}; give --site a file in an existing "
                                     "folder (the site file is {})",
                                     file.string(), folder.string(), kDefaultSiteFile));
    }
    std::string old;
    std::optional<toml::table> oldTable;
    if (std::filesystem::exists(file, ec)) {
        auto text = readText(file);
        if (!text) {
            return tl::unexpected(text.error());
        }
        auto t = parse(*text, file);
        if (!t) {
            return tl::unexpected(t.error());
        }
        old = std::move(*text);
        oldTable = std::move(*t);
    }
    auto result = oldTable ? replaceSiteKeys(old, *oldTable, file, section, body)
                           : Expected<std::string>("[" + section + "]\n" + body);
    if (!result) {
        return tl::unexpected(result.error());
    }
    auto check = parse(*result, file);
    if (!check) {
        return tl::unexpected(check.error());
    }
    if (!(*check)[section].is_table()) {
        return makeError(ErrorCode::Corrupt,
                         fmt::format("{}: [{}] did not come out as a table (is '{}' also a key at "
                                     "the top of the file?)",
                                     file.string(), section, section));
    }
    // What the appliance would say of the keys written: a calibration never writes a value the
    // site reader refuses (a stand measured in centimetres, a key it does not know), since the
    // next start would stop on it (exit 78). The file stays as it was.
    auto load = parseSiteConfig(*result, file);
    if (!load) {
        return tl::unexpected(load.error());
    }
    auto keys = parse(body, file); // the keys this calibration writes
    if (!keys) {
        return tl::unexpected(keys.error());
    }
    for (const SiteProblem& p : load->problems) {
        const std::string rest = p.key.rfind(section + ".", 0) == 0
                                         ? p.key.substr(section.size() + 1)
                                         : std::string();
        const bool ours = !rest.empty() && keys->contains(rest.substr(0, rest.find('.')));
        if (ours) {
            return makeError(ErrorCode::InvalidArgument,
                             fmt::format("{}; the calibration is not written and {} is unchanged",
                                         formatProblem(file, p), file.string()));
        }
    }
    auto saved = writeOutputFile(file, *result, "site file");
    if (!saved) {
        const std::string& why = saved.error().message;
        const bool denied = why.find(std::strerror(EACCES)) != std::string::npos ||
                            why.find(std::strerror(EROFS)) != std::string::npos;
        return makeError(saved.error().code,
                         why + (denied ? " (run as root, or give --site a writable path)" : ""));
    }
    return {};
}

std::string trackerSection(const pipeline::scene::RigidFit& fit, std::size_t points)
{
    const auto& r = fit.T_booth_tracker.rotation; // glm: r[column][row]
    const auto& t = fit.T_booth_tracker.translation;
    std::string rot;
    for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 3; ++j) {
            rot += fmt::format("{}{:.9f}", rot.empty() ? "" : ", ", r[j][i]);
        }
    }
    return fmt::format("# 'replica calibrate tracker' on {}: {} points, RMS residual {:.2f} mm, "
                       "worst point {} ({:.2f} mm).\n"
                       "# p_booth = rotation (row-major 3x3) * p_tracker + translation, metres.\n"
                       "T_booth_tracker = {{ rotation = [{}], translation = [{:.6f}, {:.6f}, "
                       "{:.6f}] }}\n"
                       "calibration_rms_m = {:.6f}\n"
                       "calibration_points = {}\n",
                       today(), points, fit.rmsM * 1e3, fit.worst + 1,
                       fit.residualsM[fit.worst] * 1e3, rot, t.x, t.y, t.z, fit.rmsM, points);
}

std::string standSection(const pipeline::scene::StandFit& fit)
{
    const auto& s = fit.stand;
    const auto& a = fit.hingeAxisPanel;
    return fmt::format("# 'replica calibrate stand' on {}: {} tilts, tape RMS {:.2f} mm, hinge "
                       "{:.2f} degrees off the panel's x axis.\n"
                       "hinge_m = [{:.6f}, {:.6f}, {:.6f}]\n"
                       "hinge_to_panel_m = {:.6f}\n"
                       "panel_width_m = {:.6f}\n"
                       "panel_height_m = {:.6f}\n"
                       "hinge_axis_panel = [{:.6f}, {:.6f}, {:.6f}]\n"
                       "calibration_rms_m = {:.6f}\n",
                       today(), fit.tiltsRad.size(), fit.rmsM * 1e3,
                       fit.axisAngleRad * 180.0 / 3.14159265358979323846, s.hingeM.x, s.hingeM.y,
                       s.hingeM.z, s.hingeToPanelM, s.panelWidthM, s.panelHeightM, a.x, a.y, a.z,
                       fit.rmsM);
}

Expected<SiteSources> readSiteSources(const std::filesystem::path& file)
{
    auto text = readText(file);
    if (!text) {
        return tl::unexpected(text.error());
    }
    auto t = parse(*text, file);
    if (!t) {
        return tl::unexpected(t.error());
    }
    SiteSources s;
    const auto* table = (*t)["sources"].as_table();
    if (table == nullptr) {
        return s;
    }
    for (const auto* kind : recordings::deviceKinds()) {
        const std::string& key = kind->name();
        const auto& node = (*table)[key];
        if (!node) {
            continue;
        }
        const auto v = node.value<std::string>();
        if (!v) {
            return makeError(ErrorCode::InvalidArgument,
                             fmt::format("{}: [sources] {} must be a string, e.g. \"sim\"",
                                         file.string(), key));
        }
        s[key] = *v;
    }
    return s;
}

Expected<pipeline::RigidTransform> readTrackerTransform(const std::filesystem::path& file)
{
    // The one reader of [tracker] (platform/site_config.cpp); problems elsewhere in the file are
    // not this reader's business (e.g. [sources], which 'run --site' reads on its own).
    auto site = loadSiteConfig(file);
    if (!site) {
        return tl::unexpected(site.error());
    }
    for (const auto& p : site->problems) {
        if (p.key.starts_with("tracker.T_booth_tracker")) {
            return makeError(ErrorCode::Corrupt, formatProblem(file, p));
        }
    }
    if (!site->config.trackerCalibrated) {
        return makeError(ErrorCode::NotFound,
                         fmt::format("{}: no [tracker] T_booth_tracker; run 'replica calibrate "
                                     "tracker'",
                                     file.string()));
    }
    return *site->config.trackerCalibrated;
}

} // namespace replica::platform
