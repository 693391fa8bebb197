// Reading and checking the site file with toml++.
#include <cmath>
#include <set>

#include <fmt/format.h>
#include <nlohmann/json.hpp>
#include <toml++/toml.h>

#include <pipeline/base/input_file.h>
#include <pipeline/base/printable.h>
#include <platform/output/display_geometry.h>
#include <platform/site_config.h>

namespace replica::platform {
namespace {

const char* typeName(toml::node_type t)
{
    switch (t) {
    case toml::node_type::table:
        return "a table";
    case toml::node_type::array:
        return "an array";
    case toml::node_type::string:
        return "a string";
    case toml::node_type::integer:
        return "an integer";
    case toml::node_type::floating_point:
        return "a number";
    case toml::node_type::boolean:
        return "a boolean";
    case toml::node_type::date:
    case toml::node_type::time:
    case toml::node_type::date_time:
        return "a date/time";
    default:
        return "nothing";
    }
}

long lineOf(const toml::node& n)
{
    return static_cast<long>(n.source().begin.line);
}

// Reads keys from the document, remembering which ones it knows, and collects problems.
class Reader
{
public:
    Reader(const toml::table& root, std::vector<SiteProblem>& problems, SiteConfig& config)
        : root_(root), problems_(problems), config_(config)
    {}

    void string(const char* section,
                const char* key,
                std::string& out,
                const std::set<std::string>& allowed = {})
    {
        const toml::node* n = find(section, key);
        if (n == nullptr) {
            return;
        }
        const auto* s = n->as_string();
        if (s == nullptr) {
            wrongType(section, key, *n, "a string");
            return;
        }
        if (!allowed.empty() && !allowed.contains(s->get())) {
            std::string list;
            for (const auto& a : allowed) {
                list += (list.empty() ? "" : ", ") + a;
            }
            problem(section, key, *n, fmt::format("'{}' is not one of: {}", s->get(), list));
            return;
        }
        out = s->get();
    }

    void boolean(const char* section, const char* key, bool& out)
    {
        const toml::node* n = find(section, key);
        if (n == nullptr) {
            return;
        }
        if (const auto* b = n->as_boolean()) {
            out = b->get();
        } else {
            wrongType(section, key, *n, "true or false");
        }
    }

    void number(const char* section, const char* key, double& out, double lo, double hi)
    {
        const toml::node* n = find(section, key);
        if (n == nullptr) {
            return;
        }
        double v = 0.0;
        if (!toDouble(section, key, *n, v)) {
            return;
        }
        if (v < lo || v > hi) {
            problem(section, key, *n, fmt::format("{} is out of range [{}, {}]", v, lo, hi));
            return;
        }
        out = v;
    }

    // A number in [lo, hi] (not 0 when lo is 0: a dimmer that turns the booth off is refused) or
    // the string "auto".
    void numberOrAuto(
            const char* section, const char* key, double& out, bool& autoOut, double lo, double hi)
    {
        const toml::node* n = find(section, key);
        if (n == nullptr) {
            return;
        }
        if (const auto* s = n->as_string()) {
            if (s->get() == "auto") {
                autoOut = true;
            } else {
                problem(section, key, *n,
                        fmt::format("'{}' is neither a number nor \"auto\"", s->get()));
            }
            return;
        }
        double v = 0.0;
        if (!toDouble(section, key, *n, v)) {
            return;
        }
        if (!(v > lo) || v > hi) {
            problem(section, key, *n, fmt::format("{} is out of range ({}, {}]", v, lo, hi));
            return;
        }
        out = v;
        autoOut = false;
    }

    template <typename Int>
    void integer(const char* section, const char* key, Int& out, std::int64_t lo, std::int64_t hi)
    {
        const toml::node* n = find(section, key);
        if (n == nullptr) {
            return;
        }
        const auto* i = n->as_integer();
        if (i == nullptr) {
            wrongType(section, key, *n, "an integer");
            return;
        }
        if (i->get() < lo || i->get() > hi) {
            problem(section, key, *n, fmt::format("{} is out of range [{}, {}]", i->get(), lo, hi));
            return;
        }
        out = static_cast<Int>(i->get());
    }

    void vec3(const char* section, const char* key, glm::dvec3& out, double lo, double hi)
    {
        const toml::node* n = find(section, key);
        if (n == nullptr) {
            return;
        }
        const auto* a = n->as_array();
        if (a == nullptr || a->size() != 3) {
            problem(section, key, *n,
                    fmt::format("expected an array of 3 numbers, got {}",
                                a == nullptr ? typeName(n->type())
                                             : fmt::format("{} elements", a->size())));
            return;
        }
        glm::dvec3 v{0.0};
        for (std::size_t i = 0; i < 3; ++i) {
            if (!toDouble(section, key, *a->get(i), v[static_cast<glm::length_t>(i)])) {
                return;
            }
            if (v[static_cast<glm::length_t>(i)] < lo || v[static_cast<glm::length_t>(i)] > hi) {
                problem(section, key, *a->get(i),
                        fmt::format("element {} = {} is out of range [{}, {}]", i + 1,
                                    v[static_cast<glm::length_t>(i)], lo, hi));
                return;
            }
        }
        out = v;
    }

    // An inline table { rotation = [9 numbers, row-major], translation = [3 numbers] }: a rigid
    // transform, the rotation orthonormal with determinant +1 (to 1e-6, as printed with 9
    // decimals), the translation within +-10 m.
    void rigid(const char* section, const char* key, std::optional<pipeline::RigidTransform>& out)
    {
        const toml::node* n = find(section, key);
        if (n == nullptr) {
            return;
        }
        const auto* t = n->as_table();
        const auto* rot = t != nullptr ? (*t)["rotation"].as_array() : nullptr;
        const auto* tr = t != nullptr ? (*t)["translation"].as_array() : nullptr;
        if (rot == nullptr || tr == nullptr || rot->size() != 9 || tr->size() != 3 ||
            t->size() != 2) {
            problem(section, key, *n,
                    "expected { rotation = [9 numbers, row-major], translation = [3 numbers] } "
                    "(as 'replica calibrate tracker' writes it)");
            return;
        }
        pipeline::RigidTransform x;
        for (std::size_t k = 0; k < 9; ++k) {
            double v = 0.0;
            if (!toDouble(section, key, *rot->get(k), v)) {
                return;
            }
            x.rotation[static_cast<int>(k % 3)][static_cast<int>(k / 3)] = v;
        }
        for (std::size_t k = 0; k < 3; ++k) {
            double v = 0.0;
            if (!toDouble(section, key, *tr->get(k), v)) {
                return;
            }
            if (std::abs(v) > 10.0) {
                problem(section, key, *tr->get(k),
                        fmt::format("translation element {} = {} is out of range [-10, 10] m",
                                    k + 1, v));
                return;
            }
            x.translation[static_cast<int>(k)] = v;
        }
        if (!pipeline::isRotation(x.rotation)) {
            problem(section, key, *n,
                    "rotation is not a rotation matrix (orthonormal, determinant +1); run "
                    "'replica calibrate tracker' again");
            return;
        }
        out = x;
    }

    // Every key of the document that no reader asked for.
    void reportUnknown()
    {
        for (auto&& [k, v] : root_) {
            const std::string section(k.str());
            if (!sections_.contains(section)) {
                problems_.push_back({section, static_cast<long>(k.source().begin.line),
                                     fmt::format("unknown section or key (known sections: {})",
                                                 sectionList())});
                continue;
            }
            const auto* t = v.as_table();
            if (t == nullptr) {
                problems_.push_back({section, lineOf(v),
                                     fmt::format("expected a table [{}], got {}", section,
                                                 typeName(v.type()))});
                continue;
            }
            for (auto&& [kk, vv] : *t) {
                const std::string key = section + "." + std::string(kk.str());
                if (!known_.contains(key)) {
                    problems_.push_back({key, static_cast<long>(kk.source().begin.line),
                                         "unknown key (misspelt? 'replica config check' lists "
                                         "the known ones in the shipped replica.toml)"});
                }
            }
        }
    }

private:
    const toml::node* find(const char* section, const char* key)
    {
        sections_.insert(section);
        known_.insert(std::string(section) + "." + key);
        const auto* t = root_.get_as<toml::table>(section);
        const toml::node* n = t != nullptr ? t->get(key) : nullptr;
        if (n != nullptr) {
            config_.lines[std::string(section) + "." + key] = lineOf(*n);
        }
        return n;
    }

    bool toDouble(const char* section, const char* key, const toml::node& n, double& v)
    {
        if (const auto* f = n.as_floating_point()) {
            v = f->get();
        } else if (const auto* i = n.as_integer()) {
            v = static_cast<double>(i->get());
        } else {
            wrongType(section, key, n, "a number");
            return false;
        }
        if (!std::isfinite(v)) {
            problem(section, key, n, "not a finite number");
            return false;
        }
        return true;
    }

    void wrongType(const char* section, const char* key, const toml::node& n, const char* want)
    {
        problem(section, key, n, fmt::format("expected {}, got {}", want, typeName(n.type())));
    }

    void problem(const char* section, const char* key, const toml::node& n, std::string what)
    {
        problems_.push_back({std::string(section) + "." + key, lineOf(n), std::move(what)});
    }

    std::string sectionList() const
    {
        std::string s;
        for (const auto& name : sections_) {
            s += (s.empty() ? "" : ", ") + name;
        }
        return s;
    }

    const toml::table& root_;
    std::vector<SiteProblem>& problems_;
    SiteConfig& config_;
    std::set<std::string> sections_;
    std::set<std::string> known_;
};

bool validSize(const std::string& s)
{
    // Each side read whole: "4294967297x1" is out of range, not 1x1.
    const auto size = parsePixelSize(s);
    return size && size->first > 0 && size->second > 0 && size->first <= 16384 &&
           size->second <= 16384;
}

nlohmann::json vec(const glm::dvec3& v)
{
    return nlohmann::json::array({v.x, v.y, v.z});
}

// The sections the calibrations write ('replica calibrate stand|tracker|spectrometer',
// platform/site_file.h), their figures for people among them.
void readCalibrated(Reader& r, SiteConfig& c)
{
    r.vec3("stand", "hinge_m", c.stand.hingeM, -kStandHingeLimitM, kStandHingeLimitM);
    r.number("stand", "hinge_to_panel_m", c.stand.hingeToPanelM, -kStandHingeToPanelLimitM,
             kStandHingeToPanelLimitM);
    r.number("stand", "panel_width_m", c.stand.panelWidthM, 0.01, 10.0);
    r.number("stand", "panel_height_m", c.stand.panelHeightM, 0.01, 10.0);
    {
        // 'replica calibrate stand' writes its figures beside the stand, for people: the hinge
        // axis as the accelerometer saw it (a unit vector in the panel's frame) and the tape's
        // RMS residual. The stand model takes the hinge along the panel's x axis.
        glm::dvec3 axis{0.0};
        double rms = 0.0;
        r.vec3("stand", "hinge_axis_panel", axis, -1.0, 1.0);
        r.number("stand", "calibration_rms_m", rms, 0.0, 1.0);
    }
    r.vec3("tracker", "rotation_deg", c.trackerRotationDeg, -360.0, 360.0);
    r.vec3("tracker", "translation_m", c.trackerTranslationM, -10.0, 10.0);
    r.rigid("tracker", "T_booth_tracker", c.trackerCalibrated);
    {
        double unused = 0.0; // the calibration's figures, for people
        r.number("tracker", "calibration_rms_m", unused, 0.0, 1.0);
        r.number("tracker", "calibration_points", unused, 0.0, 1e6);
    }
    r.integer("tracker", "port", c.trackerPort, 1, 65535);
    r.string("tracker", "bind", c.trackerBind);
    r.number("spectrometer", "stray_light_fraction", c.spectrometerStrayLight, 0.0, 0.05);
    r.number("spectrometer", "wavelength_offset_nm", c.spectrometerWavelengthOffsetNm, -5.0, 5.0);
    {
        double perY = 0.0;
        r.number("spectrometer", "direct_cdm2_per_y", perY, 1e-12, 1e12);
        if (perY > 0.0) { // given and good
            c.spectrometerDirectCdM2PerY = perY;
        }
    }
    {
        double unused = 0.0; // the calibration's figures, for people
        r.number("spectrometer", "calibration_spectra", unused, 0.0, 1e9);
        r.number("spectrometer", "calibration_spread_nm", unused, 0.0, 100.0);
    }
}

} // namespace

std::filesystem::path defaultSiteConfigPath()
{
    return REPLICA_SITE_CONFIG;
}

Expected<SiteLoad> loadSiteConfig(const std::filesystem::path& file)
{
    // Read as any input file (a regular file, at most kMaxTomlBytes, never waiting on a FIFO).
    auto text = readInputFile(file, kMaxTomlBytes, "site");
    if (!text) {
        return makeError(text.error().code,
                         fmt::format("{}; give a readable site file (a commented example is "
                                     "installed as /usr/share/replica/replica.toml)",
                                     text.error().message));
    }
    return parseSiteConfig(*text, file);
}

Expected<SiteLoad> parseSiteConfig(const std::string& text, const std::filesystem::path& file)
{
    SiteLoad out;
    out.config.source = file;
    toml::table root;
    try {
        root = toml::parse(text, file.string());
    } catch (const toml::parse_error& e) {
        const auto& where = e.source();
        return makeError(ErrorCode::InvalidArgument,
                         fmt::format("{}:{}: not valid TOML: {}", file.string(), where.begin.line,
                                     e.description()));
    }
    SiteConfig& c = out.config;
    Reader r(root, out.problems, c);
    r.string("booth", "id", c.boothId);
    r.numberOrAuto("booth", "dimmer", c.boothDimmer, c.boothDimmerAuto, 0.0, 1.0);
    r.string("booth", "dir", c.boothDir);
    r.string("booth", "light", c.light, {"auto", "direct"});
    r.string("scene", "dir", c.sceneDir);
    r.string("scene", "renderer", c.renderer); // run_resolve.cpp refuses all but "booth"
    r.boolean("render", "planner", c.renderPlanner);
    c.renderPlannerSet = root.at_path("render.planner").as_boolean() != nullptr;
    r.boolean("render", "warm_up", c.warmUp);
    r.number("render", "error_probe", c.errorProbeS, 0.0, 3600.0);
    r.string("display", "profile", c.displayProfile);
    r.boolean("display", "allow_synthetic", c.allowSynthetic);
    r.string("display", "output", c.output, {"kms", "headless"});
    std::string size = c.size;
    r.string("display", "size", size);
    if (validSize(size)) {
        c.size = size;
    } else if (const auto* n = root.at_path("display.size").node()) {
        out.problems.push_back({"display.size", lineOf(*n),
                                fmt::format("'{}' is not WIDTHxHEIGHT (1..16384 each), e.g. "
                                            "\"1920x1200\"",
                                            size)});
    }
    r.string("display", "kms_device", c.kmsDevice);
    r.string("display", "kms_connector", c.kmsConnector);
    readCalibrated(r, c);
    r.string("devices", "iio_root", c.iioRoot);
    r.string("devices", "accel_name", c.accelName);
    r.string("devices", "accel_axes", c.accelAxes);
    r.string("devices", "lamp_gpio", c.lampGpio);
    r.string("devices", "spectrometer_serial", c.spectrometerSerial);
    r.string("run", "hal", c.hal, {"live", "sim", "replay"});
    r.string("run", "replay_file", c.replayFile);
    r.number("run", "rate_hz", c.rateHz, 1.0, 240.0);
    r.number("run", "min_rate_hz", c.minRateHz, 1.0, 240.0);
    r.boolean("recording", "enabled", c.recordingEnabled);
    r.string("recording", "directory", c.recordingDirectory);
    r.integer("recording", "rotate_bytes", c.rotateBytes, 1 << 20, std::int64_t{1} << 50);
    r.integer("recording", "rotate_seconds", c.rotateSeconds, 10, 7 * 24 * 3600);
    r.integer("recording", "keep_bytes", c.keepBytes, 1 << 20, std::int64_t{1} << 55);
    r.integer("recording", "flush_ms", c.flushMs, 10, 60000);
    r.string("log", "level", c.logLevel);
    r.string("defaults", "lamp", c.defaultLamp);
    r.vec3("defaults", "eye_m", c.defaultEyeM, -10.0, 10.0);
    r.number("defaults", "tilt_deg", c.defaultTiltDeg, -90.0, 90.0);
    r.reportUnknown();
    if (c.hal == "replay" && c.replayFile.empty()) {
        out.problems.push_back(
                {"run.replay_file", 0, "run.hal = \"replay\" needs the recording to play"});
    }
    if (c.rotateBytes > c.keepBytes) {
        out.problems.push_back({"recording.keep_bytes", 0,
                                "smaller than recording.rotate_bytes: every session would be "
                                "deleted as soon as it rotates"});
    }
    return out;
}

std::string formatProblem(const std::filesystem::path& file, const SiteProblem& p)
{
    // The key and the value quoted in 'what' come from the file: a terminal escape in them is
    // shown (\x1b), never run, as in the log.
    if (p.line > 0) {
        return printable(fmt::format("{}:{}: {}: {}", file.string(), p.line, p.key, p.what));
    }
    return printable(fmt::format("{}: {}: {}", file.string(), p.key, p.what));
}

std::string SiteConfig::toJson() const
{
    nlohmann::json j{
            {"source", source.string()},
            {"booth",
             {{"id", boothId},
              {"dimmer", boothDimmerAuto ? nlohmann::json("auto") : nlohmann::json(boothDimmer)},
              {"dir", boothDir},
              {"light", light}}},
            {"spectrometer",
             {{"stray_light_fraction", spectrometerStrayLight},
              {"wavelength_offset_nm", spectrometerWavelengthOffsetNm},
              {"direct_cdm2_per_y", spectrometerDirectCdM2PerY
                                            ? nlohmann::json(*spectrometerDirectCdM2PerY)
                                            : nlohmann::json("default")}}},
            {"scene", {{"dir", sceneDir}, {"renderer", renderer}}},
            {"render",
             {{"planner",
               renderPlannerSet ? nlohmann::json(renderPlanner) : nlohmann::json("auto")},
              {"warm_up", warmUp},
              {"error_probe", errorProbeS}}},
            {"display",
             {{"profile", displayProfile},
              {"allow_synthetic", allowSynthetic},
              {"output", output},
              {"size", size},
              {"kms_device", kmsDevice},
              {"kms_connector", kmsConnector}}},
            {"stand",
             {{"hinge_m", vec(stand.hingeM)},
              {"hinge_to_panel_m", stand.hingeToPanelM},
              {"panel_width_m", stand.panelWidthM},
              {"panel_height_m", stand.panelHeightM}}},
            {"tracker",
             {{"rotation_deg", vec(trackerRotationDeg)},
              {"translation_m", vec(trackerTranslationM)},
              {"port", trackerPort},
              {"bind", trackerBind}}},
            {"devices",
             {{"iio_root", iioRoot},
              {"accel_name", accelName},
              {"accel_axes", accelAxes},
              {"lamp_gpio", lampGpio},
              {"spectrometer_serial", spectrometerSerial}}},
            {"run",
             {{"hal", hal},
              {"replay_file", replayFile},
              {"rate_hz", rateHz},
              {"min_rate_hz", minRateHz}}},
            {"recording",
             {{"enabled", recordingEnabled},
              {"directory", recordingDirectory},
              {"rotate_bytes", rotateBytes},
              {"rotate_seconds", rotateSeconds},
              {"keep_bytes", keepBytes},
              {"flush_ms", flushMs}}},
            {"log", {{"level", logLevel}}},
            {"defaults",
             {{"lamp", defaultLamp}, {"eye_m", vec(defaultEyeM)}, {"tilt_deg", defaultTiltDeg}}}};
    if (trackerCalibrated) {
        std::vector<double> rotation;
        for (int i = 0; i < 3; ++i) {
            for (int k = 0; k < 3; ++k) {
                rotation.push_back(trackerCalibrated->rotation[k][i]); // row-major
            }
        }
        j["tracker"]["T_booth_tracker"] = {{"rotation", rotation},
                                           {"translation", vec(trackerCalibrated->translation)}};
    }
    return j.dump();
}

} // namespace replica::platform
