// Site file sections: text replacement checked with toml++.
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <ctime>
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

} // namespace

Expected<void> writeSiteSection(const std::filesystem::path& file,
                                const std::string& section,
                                const std::string& body)
{
    std::string old;
    std::error_code ec;
    if (std::filesystem::exists(file, ec)) {
        auto text = readText(file);
        if (!text) {
            return tl::unexpected(text.error());
        }
        if (auto t = parse(*text, file); !t) {
            return tl::unexpected(t.error());
        }
        old = std::move(*text);
    }
    // Keep every line outside [section] and [section.*].
    std::istringstream in(old);
    std::string line;
    std::string kept;
    bool inside = false;
    while (std::getline(in, line)) {
        const std::string t = trim(line);
        if (!t.empty() && t[0] == '[') {
            inside = t == "[" + section + "]" || t.rfind("[" + section + ".", 0) == 0;
        }
        if (!inside) {
            kept += line + "\n";
        }
    }
    while (kept.size() >= 2 && kept.substr(kept.size() - 2) == "\n\n") {
        kept.pop_back();
    }
    const std::string result = kept + (kept.empty() ? "" : "\n") + "[" + section + "]\n" + body;
    auto check = parse(result, file);
    if (!check) {
        return tl::unexpected(check.error());
    }
    if (!(*check)[section].is_table()) {
        return makeError(ErrorCode::Corrupt,
                         fmt::format("{}: [{}] did not come out as a table (is '{}' also a key at "
                                     "the top of the file?)",
                                     file.string(), section, section));
    }
    if (file.has_parent_path()) {
        std::filesystem::create_directories(file.parent_path(), ec);
    }
    auto written = writeOutputFile(file, result, "site file");
    if (!written) {
        const std::string& why = written.error().message;
        const bool denied = why.find(std::strerror(EACCES)) != std::string::npos ||
                            why.find(std::strerror(EROFS)) != std::string::npos;
        return makeError(written.error().code,
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
