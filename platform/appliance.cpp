// Assembling the appliance.
#include <algorithm>
#include <array>
#include <cmath>
#include <fstream>
#include <iterator>
#include <numbers>
#include <span>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <hal/replay/replay_source.h>
#include <hal/sim/sim_devices.h>
#include <pipeline/base/data_dir.h>
#include <pipeline/base/input_file.h>
#include <pipeline/booth/booth_model.h>
#include <pipeline/colour/spectral_table.h>
#include <pipeline/display/display_inverse.h>
#include <pipeline/display/display_profile.h>
#include <pipeline/display/nominal_display.h>
#include <pipeline/render/gles_renderer.h>
#include <pipeline/shading/realtime_model.h>
#include <pipeline/spectral/adaptive_encoding.h>
#include <pipeline/spectral/representation_catalogue.h>
#include <platform/appliance.h>
#include <platform/booth_dimmer.h>
#include <platform/logging.h>
#include <platform/loop/frame_digest.h>
#include <platform/run_config_schema.h>

namespace replica::platform {

std::int64_t RunConfig::periodNs() const
{
    return static_cast<std::int64_t>(std::llround(1e9 / rateHz));
}

std::string RunConfig::toJson() const
{
    nlohmann::json j{{"width", width},
                     {"height", height},
                     {"rate_hz", rateHz},
                     {"booth", booth},
                     {"scene", scene},
                     {"basis", basis},
                     {"lights_u", lightsU},
                     {"lights_v", lightsV},
                     {"spectrometer_calibration", spectrometerCalibration},
                     {"display", display},
                     {"display_peak_cd_m2", displayPeakCdM2},
                     {"display_black_cd_m2", displayBlackCdM2},
                     {"renderer", renderer},
                     {"scene_dir", sceneDir},
                     {"scene_digest", sceneDigest},
                     {"booth_lights", boothLights},
                     {"specular_samples", specularSamples},
                     {"specular_grid", specularGrid},
                     {"diffuse_grid", diffuseGrid},
                     {"area_lights", areaLights},
                     {"booth_dimmer", boothDimmer},
                     {"booth_dimmer_auto", boothDimmerAuto || boothDimmerChosenAuto},
                     {"cache_slices", cacheSlices},
                     {"render_profile", renderProfile()},
                     {"horizon_directions", horizonDirections},
                     {"display_digest", displayDigest},
                     {"display_inverse", displayInverse},
                     {"gamut_mapping", gamutMapping},
                     {"viewing_compensation", viewingCompensation},
                     {"flare_subtraction", flareSubtraction},
                     {"false_colour", falseColour},
                     {"stand_hinge_m", {stand.hingeM.x, stand.hingeM.y, stand.hingeM.z}},
                     {"stand_hinge_to_panel_m", stand.hingeToPanelM},
                     {"panel_width_m", stand.panelWidthM},
                     {"panel_height_m", stand.panelHeightM},
                     {"default_lamp", defaultLamp},
                     {"default_eye_m", {defaultEyeM.x, defaultEyeM.y, defaultEyeM.z}},
                     {"default_tilt_rad", defaultTiltRad}};
    if (renderProfile() == pipeline::render::kExplicitRenderProfile) {
        // Switches no profile names: one key each, as recordings made before profiles hold them.
        j["hardware_filter"] = switches.hardwareFilter;
        j["specular_lod_bias"] = switches.specularLodBias;
        j["specular_nearest_level"] = switches.specularNearestLevel;
        j["horizon_spread"] = switches.horizonSpread;
        j["horizon_half"] = switches.horizonHalf;
        j["horizon_bilinear"] = switches.horizonBilinear;
        j["specular_branch_free"] = switches.specularBranchFree;
        j["specular_exact_level"] = switches.specularExactLevel;
        j["texel_exact_ties"] = switches.texelExactTies;
        j["horizon_pick"] = switches.horizonPick;
        j["surround_illuminance"] = switches.surroundIlluminance;
        j["viewing_filtered"] = switches.viewingFiltered;
    }
    {
        std::vector<double> rotation;
        for (int i = 0; i < 3; ++i) {
            for (int k = 0; k < 3; ++k) {
                rotation.push_back(trackerInBooth.rotation[k][i]); // row-major
            }
        }
        const glm::dvec3& t = trackerInBooth.translation;
        j["t_booth_tracker"] = {{"rotation", rotation}, {"translation", {t.x, t.y, t.z}}};
    }
    if (!plannedLamps.empty()) {
        nlohmann::json lamps = nlohmann::json::object();
        for (const auto& [name, p] : plannedLamps) {
            lamps[name] = {{"lights", p.lights},
                           {"specular_samples", p.specularSamples},
                           {"horizon_directions", p.horizonDirections}};
        }
        j["planned_lamps"] = lamps;
    }
    return j.dump();
}

namespace {

// The render switches a run configuration records: "render_profile" N >= 1 names them; without
// it (recordings made before profiles) or with 0, one key each, an absent key being the switch
// as it was before it existed (render profile 1's).
Expected<pipeline::render::RenderSwitches> readSwitches(const nlohmann::json& j)
{
    using pipeline::render::kExplicitRenderProfile;
    const int profile = j.value("render_profile", kExplicitRenderProfile);
    static constexpr const char* kKeys[] = {
            "hardware_filter",      "specular_lod_bias",    "specular_nearest_level",
            "horizon_spread",       "horizon_half",         "horizon_bilinear",
            "specular_branch_free", "specular_exact_level", "texel_exact_ties",
            "horizon_pick",         "surround_illuminance", "viewing_filtered"};
    if (profile != kExplicitRenderProfile) {
        for (const char* key : kKeys) {
            if (j.contains(key)) {
                return makeError(ErrorCode::Corrupt,
                                 fmt::format("run configuration: render_profile {} and the "
                                             "explicit switch '{}' both given; a profile fixes "
                                             "every switch",
                                             profile, key));
            }
        }
        auto p = pipeline::render::findRenderProfile(profile);
        if (!p) {
            return makeError(ErrorCode::Unsupported,
                             fmt::format("run configuration: {}", p.error().message));
        }
        return (*p)->switches;
    }
    // Profile 1 is every switch as it was before it existed: what an absent key means. (A switch
    // added after profiles has no key: recordings that name no profile replay it as then.)
    pipeline::render::RenderSwitches s = (*pipeline::render::findRenderProfile(1))->switches;
    s.hardwareFilter = j.value("hardware_filter", s.hardwareFilter);
    s.specularNearestLevel = j.value("specular_nearest_level", s.specularNearestLevel);
    s.horizonSpread = j.value("horizon_spread", s.horizonSpread);
    s.horizonHalf = j.value("horizon_half", s.horizonHalf);
    s.horizonBilinear = j.value("horizon_bilinear", s.horizonBilinear);
    s.specularBranchFree = j.value("specular_branch_free", s.specularBranchFree);
    s.specularExactLevel = j.value("specular_exact_level", s.specularExactLevel);
    s.texelExactTies = j.value("texel_exact_ties", s.texelExactTies);
    s.horizonPick = j.value("horizon_pick", s.horizonPick);
    s.specularLodBias = j.value("specular_lod_bias", s.specularLodBias);
    s.surroundIlluminance = j.value("surround_illuminance", s.surroundIlluminance);
    s.viewingFiltered = j.value("viewing_filtered", s.viewingFiltered);
    return s;
}

} // namespace

Expected<RunConfig> RunConfig::fromJson(const std::string& json, std::vector<std::string>* warnings)
{
    RunConfig c;
    try {
        const auto j = nlohmann::json::parse(json);
        if (auto ok = validateJson(j, runConfigSchema(), "run configuration", warnings); !ok) {
            return tl::unexpected(ok.error());
        }
        c.width = j.at("width").get<int>();
        c.height = j.at("height").get<int>();
        c.rateHz = j.at("rate_hz").get<double>();
        c.booth = j.at("booth").get<std::string>();
        c.scene = j.at("scene").get<std::string>();
        c.basis = j.at("basis").get<std::string>();
        c.lightsU = j.at("lights_u").get<int>();
        c.lightsV = j.at("lights_v").get<int>();
        c.spectrometerCalibration = j.at("spectrometer_calibration").get<std::string>();
        c.display = j.at("display").get<std::string>();
        c.displayPeakCdM2 = j.at("display_peak_cd_m2").get<double>();
        c.displayBlackCdM2 = j.at("display_black_cd_m2").get<double>();
        // Absent in recordings made before the booth renderer: those replay with the flat one.
        c.renderer = j.value("renderer", std::string("flat"));
        c.sceneDir = j.value("scene_dir", c.sceneDir);
        c.sceneDigest = j.value("scene_digest", std::string());
        c.boothLights = j.value("booth_lights", c.boothLights);
        c.specularSamples = j.value("specular_samples", c.specularSamples);
        // Absent before the specular grid: those recordings were shaded per pixel.
        c.specularGrid = j.value("specular_grid", 0);
        c.diffuseGrid = j.value("diffuse_grid", 0);
        c.areaLights = j.value("area_lights", 0);
        // Absent before the booth dimmer: those recordings replay undimmed. A recorded "auto"
        // is the number it chose; a replay never chooses again.
        c.boothDimmer = j.value("booth_dimmer", 1.0);
        c.boothDimmerChosenAuto = j.value("booth_dimmer_auto", false);
        c.cacheSlices = j.value("cache_slices", 1);
        if (auto switches = readSwitches(j); switches) {
            c.switches = *switches;
        } else {
            return tl::unexpected(switches.error());
        }
        c.horizonDirections = j.value("horizon_directions", c.horizonDirections);
        // Recordings made before display profiles had none of these: the plain pass 2 they had
        // was on-axis, without flare subtraction.
        c.displayDigest = j.value("display_digest", std::string());
        c.displayInverse = j.value("display_inverse", std::string("analytic"));
        c.gamutMapping = j.value("gamut_mapping", std::string("hue"));
        c.viewingCompensation = j.value("viewing_compensation", false);
        c.flareSubtraction = j.value("flare_subtraction", false);
        c.falseColour = j.value("false_colour", false);
        if (j.contains("t_booth_tracker")) {
            const auto r = j.at("t_booth_tracker").at("rotation").get<std::vector<double>>();
            const auto t = j.at("t_booth_tracker").at("translation").get<std::vector<double>>();
            if (r.size() != 9 || t.size() != 3) {
                return makeError(ErrorCode::Corrupt,
                                 "run configuration: t_booth_tracker needs 9 + 3 numbers");
            }
            pipeline::RigidTransform x;
            for (std::size_t k = 0; k < 9; ++k) {
                x.rotation[static_cast<int>(k % 3)][static_cast<int>(k / 3)] = r[k];
            }
            x.translation = {t[0], t[1], t[2]};
            if (!pipeline::isRotation(x.rotation)) {
                return makeError(ErrorCode::Corrupt,
                                 "run configuration: t_booth_tracker/rotation is not a rotation "
                                 "(orthonormal, determinant +1)");
            }
            c.trackerInBooth = x;
        }
        // Absent before the site file: the constants the code had then (the defaults).
        const auto vec3 = [&j](const char* key, glm::dvec3& v) {
            if (j.contains(key)) {
                const auto a = j.at(key).get<std::vector<double>>();
                if (a.size() != 3) {
                    throw std::runtime_error(fmt::format("{}: expected 3 numbers", key));
                }
                v = {a[0], a[1], a[2]};
            }
        };
        vec3("stand_hinge_m", c.stand.hingeM);
        c.stand.hingeToPanelM = j.value("stand_hinge_to_panel_m", c.stand.hingeToPanelM);
        c.stand.panelWidthM = j.value("panel_width_m", c.stand.panelWidthM);
        c.stand.panelHeightM = j.value("panel_height_m", c.stand.panelHeightM);
        // Recordings made before t_booth_tracker was recorded whole: the angles (degrees) and
        // translation of the site file, absent = the fixed mounting.
        if (!j.contains("t_booth_tracker")) {
            glm::dvec3 rotationDeg{0.0};
            glm::dvec3 translationM = pipeline::kDefaultTrackerInBoothM;
            vec3("tracker_rotation_deg", rotationDeg);
            vec3("tracker_translation_m", translationM);
            c.trackerInBooth = pipeline::rigidFromDegrees(rotationDeg, translationM);
        }
        c.defaultLamp = j.value("default_lamp", std::string());
        vec3("default_eye_m", c.defaultEyeM);
        c.defaultTiltRad = j.value("default_tilt_rad", c.defaultTiltRad);
        // Absent before the planner in the loop: the fixed rules.
        if (j.contains("planned_lamps")) {
            for (const auto& [name, l] : j.at("planned_lamps").items()) {
                LampPlan p;
                p.lights = l.at("lights").get<int>();
                p.specularSamples = l.at("specular_samples").get<int>();
                p.horizonDirections = l.at("horizon_directions").get<int>();
                if (p.lights < 1 || p.lights > 256 || p.specularSamples < 0 ||
                    p.specularSamples > 256 || p.horizonDirections < 0 ||
                    p.horizonDirections > 32) {
                    throw std::runtime_error(
                            fmt::format("planned_lamps.{}: a count out of range", name));
                }
                c.plannedLamps[name] = p;
            }
        }
    } catch (const std::exception& e) {
        return makeError(ErrorCode::Corrupt, fmt::format("run configuration: {}", e.what()));
    }
    if (!frameSizeOk(c.width, c.height) || !(c.rateHz >= 1.0) || c.rateHz > 1000.0 ||
        c.lightsU <= 0 || c.lightsV <= 0 ||
        static_cast<long long>(c.lightsU) * static_cast<long long>(c.lightsV) > 256 ||
        !std::isfinite(c.displayPeakCdM2) || !std::isfinite(c.displayBlackCdM2) ||
        c.boothLights < 1 || c.boothLights > 256 || c.specularSamples < kAutoSpecularSamples ||
        c.specularSamples > 256 || c.horizonDirections < 0 || c.horizonDirections > 32 ||
        c.specularGrid < kAutoSpecularGrid || c.specularGrid > 256 ||
        c.diffuseGrid < kAutoDiffuseGrid || c.diffuseGrid > 256 ||
        !(std::abs(c.switches.specularLodBias) <= pipeline::shading::kMaxSpecularLodBias) ||
        c.cacheSlices < 1 || c.cacheSlices > kMaxCacheSlices || c.areaLights < kAutoAreaLights ||
        c.areaLights > 1 || !(c.boothDimmer > 0.0) || c.boothDimmer > 1.0) {
        return makeError(
                ErrorCode::InvalidArgument,
                fmt::format(
                        "run configuration: size {}x{} (each side 1-{}, at most "
                        "{}:1), rate {} Hz (1-1000), lights {}x{} (at most 256), "
                        "display peak/black, specular samples, specular or diffuse "
                        "grid, specular lod bias, horizon directions, cache slices, area lights "
                        "or booth dimmer (0 to 1) out of range",
                        c.width, c.height, kMaxFrameSide, kMaxFrameAspect, c.rateHz, c.lightsU,
                        c.lightsV));
    }
    const auto finite3 = [](const glm::dvec3& v) {
        return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
    };
    if (!finite3(c.stand.hingeM) || !std::isfinite(c.stand.hingeToPanelM) ||
        !(c.stand.panelWidthM > 0.0 && c.stand.panelWidthM <= 10.0) ||
        !(c.stand.panelHeightM > 0.0 && c.stand.panelHeightM <= 10.0) ||
        !finite3(c.trackerInBooth.translation) ||
        !pipeline::isRotation(c.trackerInBooth.rotation) || !finite3(c.defaultEyeM) ||
        !std::isfinite(c.defaultTiltRad)) {
        return makeError(ErrorCode::InvalidArgument,
                         "run configuration: stand, panel size, tracker transform or default "
                         "eye/tilt not finite or out of range");
    }
    if (!(c.stand.panelWidthM >= 0.02 && c.stand.panelWidthM <= 10.0) ||
        !(c.stand.panelHeightM >= 0.02 && c.stand.panelHeightM <= 10.0)) {
        return makeError(ErrorCode::InvalidArgument,
                         fmt::format("run configuration: panel size {}x{} m out of range (0.02 "
                                     "to 10 m each)",
                                     c.stand.panelWidthM, c.stand.panelHeightM));
    }
    if (c.renderer != "booth" && c.renderer != "flat") {
        return makeError(ErrorCode::InvalidArgument,
                         fmt::format("run configuration: renderer '{}' is not 'booth' or 'flat'",
                                     c.renderer));
    }
    if ((c.displayInverse != "analytic" && c.displayInverse != "lut3d") ||
        (c.gamutMapping != "hue" && c.gamutMapping != "clip")) {
        return makeError(ErrorCode::InvalidArgument,
                         fmt::format("run configuration: display inverse '{}' (analytic, lut3d) "
                                     "or gamut mapping '{}' (hue, clip) unknown",
                                     c.displayInverse, c.gamutMapping));
    }
    return c;
}

std::filesystem::path resolveSceneDir(const std::string& sceneDir)
{
    const std::filesystem::path p(sceneDir);
    return p.is_relative() ? dataDir() / p : p;
}

namespace {

// 'p' lies inside 'root' once both are made absolute and '..' and links resolved as far as
// they exist.
bool inside(const std::filesystem::path& p, const std::filesystem::path& root)
{
    std::error_code ec;
    const auto a = std::filesystem::weakly_canonical(std::filesystem::absolute(p, ec), ec);
    if (ec) {
        return false;
    }
    const auto r = std::filesystem::weakly_canonical(std::filesystem::absolute(root, ec), ec);
    if (ec) {
        return false;
    }
    const auto rel = a.lexically_relative(r);
    return !rel.empty() && *rel.begin() != ".." && !rel.is_absolute();
}

Expected<void> checkReference(const std::string& key,
                              const std::string& value,
                              const std::vector<std::filesystem::path>& roots)
{
    const std::filesystem::path p(value);
    bool dotdot = false;
    for (const auto& part : p) {
        dotdot = dotdot || part == "..";
    }
    std::string rootList = dataDir().string();
    for (const auto& r : roots) {
        rootList += ", " + r.string();
    }
    if (value.empty() || dotdot || value.find('\0') != std::string::npos) {
        return makeError(ErrorCode::InvalidArgument,
                         fmt::format("the recording's {} '{}' is not a name inside the data "
                                     "folder ('..' or empty); refused",
                                     key, value.substr(0, 200)));
    }
    if (p.is_relative()) {
        return inside(dataDir() / p, dataDir())
                       ? Expected<void>{}
                       : makeError(ErrorCode::InvalidArgument,
                                   fmt::format("the recording's {} '{}' leads out of the data "
                                               "folder {} (a link?); refused",
                                               key, value.substr(0, 200), dataDir().string()));
    }
    bool ok = inside(p, dataDir());
    for (const auto& r : roots) {
        ok = ok || inside(p, r);
    }
    if (!ok) {
        return makeError(ErrorCode::InvalidArgument,
                         fmt::format("the recording's {} is '{}', outside the data folders ({}); "
                                     "replay opens only files there: copy it under one and pass "
                                     "that folder with --data-root DIR",
                                     key, value.substr(0, 200), rootList));
    }
    return {};
}

} // namespace

Expected<void> checkRecordedReferences(const RunConfig& config,
                                       const std::vector<std::filesystem::path>& roots,
                                       bool allowUndigested)
{
    if (config.renderer == "booth") {
        if (auto ok = checkReference("scene_dir", config.sceneDir, roots); !ok) {
            return ok;
        }
        if (config.sceneDigest.empty() && !allowUndigested) {
            return makeError(ErrorCode::InvalidArgument,
                             fmt::format("the recording holds no digest of its scene '{}', so "
                                         "the scene replayed cannot be checked against the one "
                                         "recorded; pass --allow-undigested to replay it anyway",
                                         config.sceneDir.substr(0, 200)));
        }
    }
    if (config.display != kUncalibratedDisplay) {
        if (auto ok = checkReference("display", config.display, roots); !ok) {
            return ok;
        }
        if (config.displayDigest.empty() && !allowUndigested) {
            return makeError(ErrorCode::InvalidArgument,
                             fmt::format("the recording holds no digest of its display profile "
                                         "'{}'; pass --allow-undigested to replay it anyway",
                                         config.display.substr(0, 200)));
        }
    }
    if (auto ok = checkReference("spectrometer_calibration", config.spectrometerCalibration, {});
        !ok) {
        return ok;
    }
    if (std::filesystem::path(config.spectrometerCalibration).is_absolute()) {
        return makeError(ErrorCode::InvalidArgument,
                         fmt::format("the recording's spectrometer_calibration '{}' is not a "
                                     "name inside the data folder; refused",
                                     config.spectrometerCalibration.substr(0, 200)));
    }
    return {};
}

Expected<std::string> sceneDigest(const std::filesystem::path& dir)
{
    std::uint64_t h = 14695981039346656037ull;
    for (const char* name : {"scene.json", "channels.exr", "height.exr", "material.exr"}) {
        // Regular files only: a FIFO would block here and a directory throw from the stream.
        if (auto ok = checkInputFile(dir / name, kMaxImageBytes, "scene"); !ok) {
            if (ok.error().code == ErrorCode::NotFound) {
                return makeError(ErrorCode::NotFound, fmt::format("{}: cannot read the scene file",
                                                                  (dir / name).string()));
            }
            return tl::unexpected(ok.error());
        }
        std::ifstream in(dir / name, std::ios::binary);
        if (!in) {
            return makeError(ErrorCode::NotFound,
                             fmt::format("{}: cannot read the scene file", (dir / name).string()));
        }
        for (const char c : std::string(name)) {
            h = (h ^ static_cast<unsigned char>(c)) * 1099511628211ull;
        }
        std::array<char, 65536> buf{};
        while (in.read(buf.data(), buf.size()) || in.gcount() > 0) {
            for (std::streamsize i = 0; i < in.gcount(); ++i) {
                h = (h ^ static_cast<unsigned char>(buf[static_cast<std::size_t>(i)])) *
                    1099511628211ull;
            }
        }
    }
    return fmt::format("{:016x}", h);
}

std::string displayProfileId(const RunConfig& config, const std::string& profileName)
{
    if (config.display == kUncalibratedDisplay) {
        return fmt::format("{} (uncalibrated nominal model)", kUncalibratedDisplay);
    }
    return fmt::format("{} ({}, fnv1a64 {})", profileName, config.display, config.displayDigest);
}

pipeline::shading::RenderSettings boothRenderSettings(const RunConfig& config)
{
    pipeline::shading::RenderSettings s;
    s.lights = config.boothLights;
    s.specularSamples = config.specularSamples;
    s.specularGrid = config.specularGrid;
    s.diffuseGrid = config.diffuseGrid;
    s.horizonDirections = config.horizonDirections;
    pipeline::render::applyRenderSwitches(config.switches, s);
    s.areaLights = config.areaLights != 0;
    s.cacheSlices = config.cacheSlices;
    // The display pass subtracts the screen's flare when asked to (issue 6): then pass 1 must not.
    s.subtractFlare = !config.flareSubtraction;
    return s;
}

namespace {

// The booth renderer's pass 1: the booth model, the scene folder, the settings.
// The geometry rules (docs/architecture.md, Outputs): on a display, a run's frame is the mode's
// size and, with no configured panel size, the panel is the size the display's EDID gives; the
// renderer maps the frame onto the panel, so a surface shows at its physical size where the
// pixels are square.
void applyDisplayGeometry(RunConfig& config, const Output& output, const OutputChoice& choice)
{
    auto log = logger("output");
    const auto display = output.display();
    if (display && choice.frameFromMode) {
        config.width = display->width;
        config.height = display->height;
    }
    if (display && choice.panelFromDisplay) {
        const PanelSize panel =
                resolvePanelSize(std::nullopt, display->edidSize, config.stand.panelWidthM,
                                 config.stand.panelHeightM);
        config.stand.panelWidthM = panel.widthM;
        config.stand.panelHeightM = panel.heightM;
        if (panel.source == "edid") {
            log->info("panel {:.0f}x{:.0f} mm from the EDID of {}", panel.widthM * 1000.0,
                      panel.heightM * 1000.0, display->connector);
        } else {
            log->warn("{} gives no physical size: the panel is taken as {:.0f}x{:.0f} mm; set "
                      "its active area with --panel-size-mm",
                      display->connector, panel.widthM * 1000.0, panel.heightM * 1000.0);
        }
    }
    const PanelSize panel{config.stand.panelWidthM, config.stand.panelHeightM, ""};
    if (const double e = pixelAspectError(panel, config.width, config.height); e > 0.02) {
        log->warn("a {}x{} frame on a {:.0f}x{:.0f} mm panel has pixels {:.1f}% off square: "
                  "surfaces show stretched; check the panel size and the mode",
                  config.width, config.height, config.stand.panelWidthM * 1000.0,
                  config.stand.panelHeightM * 1000.0, 100.0 * e);
    }
}

// The site's [booth] dimmer = "auto": the scale that brings the surface's 99th percentile of Y,
// under the brightest of the booth's lamps at the stand's brightest tilt of 0, 15, 30, 45 and 60
// degrees (the CPU model on a 32 x 20 probe frame from the default eye, each lamp's own adaptive
// basis), to the panel's peak. Logs the scale and what it does to the display's error on the
// probe (over-peak share, dE00 against the dimmed scene), per lamp at its brightest tilt.
void chooseBoothDimmer(RunConfig& config,
                       const pipeline::render::BoothSceneSetup& setup,
                       const pipeline::display::DisplayModel& displayModel)
{
    namespace sh = pipeline::shading;
    auto log = logger("booth");
    std::vector<sh::XyzFrame> frames; // per lamp, the frame of its brightest tilt
    std::vector<std::string> names;
    for (const auto& name : setup.lamps) {
        const pipeline::booth::BoothLight* light = setup.booth.find(name);
        if (light == nullptr) {
            continue;
        }
        pipeline::colour::ChannelBasis basis = setup.basis;
        if (setup.adaptive) {
            if (auto b = setup.adaptive->basisFor(light->spd)) {
                basis = std::move(*b);
            }
        }
        const auto ps = sh::prepareScene(setup.scene, std::max(setup.settings.horizonDirections, 1),
                                         0.01, basis);
        const auto pl = sh::prepareLight(*light, setup.observer, setup.settings.lights, basis);
        double brightest = -1.0;
        sh::XyzFrame keep;
        for (const double tiltDeg : {0.0, 15.0, 30.0, 45.0, 60.0}) {
            sh::View view;
            view.panel = pipeline::scene::panelPose(config.stand,
                                                    pipeline::scene::degreesToRadians(tiltDeg));
            view.eye = config.defaultEyeM;
            view.pixelsX = 32;
            view.pixelsY = 20;
            sh::XyzFrame f = sh::renderRealtime(ps, pl, view, setup.observer, setup.settings);
            const double q = quantileY({f}, 0.99);
            if (q > brightest) {
                brightest = q;
                keep = std::move(f);
            }
        }
        frames.push_back(std::move(keep));
        names.push_back(name);
    }
    const double peakY = displayModel.whiteXyz().y;
    double scale = 1.0;
    for (const auto& f : frames) {
        scale = std::min(scale, autoBoothDimmer({f}, peakY));
    }
    config.boothDimmer = scale;
    config.boothDimmerAuto = false;
    config.boothDimmerChosenAuto = true;
    auto inverse = pipeline::display::DisplayInverse::build(displayModel);
    if (!inverse) {
        log->info("booth dimmer (auto): {:.4f} for the panel's peak {:.0f} cd/m^2",
                  config.boothDimmer, peakY);
        return;
    }
    for (std::size_t i = 0; i < frames.size(); ++i) {
        const DimmerEffect before = boothDimmerEffect(frames[i], 1.0, *inverse);
        const DimmerEffect after = boothDimmerEffect(frames[i], config.boothDimmer, *inverse);
        log->info("booth dimmer (auto) {:.4f} for the panel's peak {:.0f} cd/m^2; lamp {} at its "
                  "brightest tilt: surface above the peak {:.1f}% -> {:.1f}%, display dE00 mean "
                  "/ p95 / max {:.2f} / {:.2f} / {:.2f} -> {:.2f} / {:.2f} / {:.2f}",
                  config.boothDimmer, peakY, names[i], 100.0 * before.overPeakFraction,
                  100.0 * after.overPeakFraction, before.de00Mean, before.de00P95, before.de00Max,
                  after.de00Mean, after.de00P95, after.de00Max);
    }
}

Expected<std::shared_ptr<pipeline::render::BoothScenePass>>
makeBoothScene(RunConfig& config,
               const pipeline::booth::Booth& booth,
               const pipeline::colour::ChannelBasis& basis,
               const pipeline::colour::Observer& observer,
               std::shared_ptr<const pipeline::spectral::AdaptiveEncoder> adaptive,
               const pipeline::display::DisplayModel& displayModel)
{
    const auto dir = resolveSceneDir(config.sceneDir);
    auto digest = sceneDigest(dir);
    if (!digest) {
        return tl::unexpected(digest.error());
    }
    if (!config.sceneDigest.empty() && config.sceneDigest != *digest) {
        return makeError(ErrorCode::Corrupt,
                         fmt::format("{}: the scene has changed since it was recorded (digest {}, "
                                     "recorded {}); replay needs the recorded scene",
                                     dir.string(), *digest, config.sceneDigest));
    }
    config.sceneDigest = *digest;
    auto scene = pipeline::surface::loadScene(dir);
    if (!scene) {
        return tl::unexpected(scene.error());
    }
    config.scene = scene->name;
    pipeline::render::BoothSceneSetup setup;
    setup.stand = config.stand;
    setup.booth = booth;
    for (const auto& light : booth.lights) {
        setup.lamps.push_back(light.name);
    }
    setup.scene = std::move(*scene);
    setup.basis = basis;
    setup.adaptive = std::move(adaptive);
    setup.observer = observer;
    setup.stand = config.stand;
    // The counts chosen for the scene, recorded.
    if (config.specularSamples == kAutoSpecularSamples) {
        config.specularSamples = pipeline::shading::defaultSpecularSamples(setup.scene);
    }
    if (config.specularGrid == kAutoSpecularGrid) {
        config.specularGrid = pipeline::shading::defaultSpecularGrid(setup.scene);
    }
    if (config.diffuseGrid == kAutoDiffuseGrid) {
        config.diffuseGrid = pipeline::shading::defaultDiffuseGrid(setup.scene);
    }
    if (config.areaLights == kAutoAreaLights) {
        config.areaLights = pipeline::shading::defaultAreaLights(setup.scene) ? 1 : 0;
    }
    setup.settings = boothRenderSettings(config);
    // The planner in the loop: the scene's cached plan (computed once when missing), recorded.
    if (config.planner && config.plannedLamps.empty()) {
        auto plan = loadOrComputeRenderPlan(dir, dataDir() / "booth", config.basis,
                                            config.plannerCache.empty()
                                                    ? defaultPlanCacheDir()
                                                    : std::filesystem::path(config.plannerCache));
        if (!plan) {
            return tl::unexpected(plan.error());
        }
        for (const auto& lamp : setup.lamps) {
            const auto it = plan->lamps.find(lamp);
            if (it != plan->lamps.end()) {
                config.plannedLamps[lamp] = it->second;
            }
        }
    }
    for (const auto& [name, p] : config.plannedLamps) {
        pipeline::render::LampSettings ls;
        ls.lights = p.lights;
        ls.specularSamples = p.specularSamples;
        ls.horizonDirections = p.horizonDirections;
        setup.perLamp[name] = ls;
        logger("planner")->info("lamp {}: {} lights, {} specular samples, {} horizon directions",
                                name, p.lights, p.specularSamples, p.horizonDirections);
    }
    if (config.boothDimmerAuto) {
        chooseBoothDimmer(config, setup, displayModel);
    }
    setup.luminanceScale = config.boothDimmer;
    if (config.boothDimmer != 1.0) {
        for (auto& light : setup.booth.lights) {
            for (double& t : light.luminance.cdM2) {
                t *= config.boothDimmer;
            }
        }
    }
    auto pass = pipeline::render::BoothScenePass::create(std::move(setup));
    if (!pass) {
        return tl::unexpected(pass.error());
    }
    return std::shared_ptr<pipeline::render::BoothScenePass>(std::move(*pass));
}

// The display pass's setup from the configuration: the profile (checked against the digest a
// recording holds) or the nominal model.
Expected<pipeline::render::DisplayPassSetup> displaySetup(RunConfig& config, std::string& id)
{
    namespace pd = pipeline::display;
    pipeline::render::DisplayPassSetup d;
    if (config.display == kUncalibratedDisplay) {
        d.model = pd::nominalDisplayModel(kUncalibratedDisplay, config.displayPeakCdM2,
                                          config.displayBlackCdM2);
    } else {
        std::filesystem::path path(config.display);
        if (path.is_relative()) {
            path = dataDir() / path;
        }
        auto read = readInputFile(path, kMaxJsonBytes, "display profile");
        if (!read) {
            if (read.error().code != ErrorCode::NotFound) {
                return tl::unexpected(read.error());
            }
            return makeError(ErrorCode::NotFound,
                             fmt::format("no display profile at {}: characterise the panel "
                                         "('replica display fit MEAS.csv --out PROFILE') and pass "
                                         "--display-profile PROFILE, or run --uncalibrated",
                                         path.string()));
        }
        const std::string& bytes = *read;
        const std::string digest = fmt::format(
                "{:016x}", fnv1a64(std::span(reinterpret_cast<const std::uint8_t*>(bytes.data()),
                                             bytes.size())));
        if (!config.displayDigest.empty() && config.displayDigest != digest) {
            return makeError(ErrorCode::InvalidArgument,
                             fmt::format("display profile {} has changed since it was recorded "
                                         "(fnv1a64 {} now, {} then): restore that file to replay "
                                         "the recording as it was",
                                         path.string(), digest, config.displayDigest));
        }
        config.displayDigest = digest;
        auto model = pd::profileFromJson(bytes, path.string());
        if (!model) {
            return tl::unexpected(model.error());
        }
        d.model = std::move(*model);
    }
    d.method = config.displayInverse == "lut3d" ? pipeline::render::InverseMethod::Lut3d
                                                : pipeline::render::InverseMethod::Analytic;
    d.gamut = config.gamutMapping == "clip" ? pd::GamutMode::Clip : pd::GamutMode::HueKeeping;
    d.viewingCompensation = config.viewingCompensation;
    d.viewingFiltered = config.switches.viewingFiltered;
    d.flareSubtraction = config.flareSubtraction;
    d.falseColour = config.falseColour;
    id = displayProfileId(config, d.model.name);
    return d;
}

} // namespace

Expected<std::unique_ptr<Appliance>> buildAppliance(const RunConfig& configIn,
                                                    const OutputChoice& outputChoice)
{
    RunConfig config = configIn;
    std::string displayId;
    auto display = displaySetup(config, displayId);
    if (!display) {
        return tl::unexpected(display.error());
    }
    const std::string dir = dataDir().string();
    auto app = std::make_unique<Appliance>();
    app->config = config;
    // Channel bases: adaptive_k6 (re-encoded for each light; the default), box6 (built in; what
    // the first recordings used) or one fitted by 'replica spectral fit' under data/channels/
    // (docs/accuracy.md).
    const bool adaptive = config.basis == kAdaptiveBasis;
    const std::vector<std::string> bases = pipeline::spectral::channelBasisNames();
    const bool knownBasis = std::find(bases.begin(), bases.end(), config.basis) != bases.end();
    const bool knownScene = config.renderer == "booth" || config.scene == "colorchecker";
    if (config.booth != "replica-booth-1" || !knownScene || !knownBasis) {
        return makeError(ErrorCode::NotFound,
                         fmt::format("unknown booth '{}', scene '{}' or basis '{}' (this build has "
                                     "replica-booth-1, colorchecker, and bases {})",
                                     config.booth, config.scene, config.basis,
                                     fmt::join(bases, ", ")));
    }
    if (adaptive && config.renderer != "booth") {
        return makeError(ErrorCode::InvalidArgument,
                         "basis adaptive_k6 re-encodes the booth renderer's surface scene; the "
                         "flat renderer needs a fixed basis (--basis replica_k6)");
    }
    auto booth = pipeline::scene::loadDefaultBooth(dir);
    if (!booth) {
        return tl::unexpected(booth.error());
    }
    app->booth = *booth;
    auto observer = pipeline::colour::loadCie1931(dir);
    if (!observer) {
        return tl::unexpected(observer.error());
    }
    auto calibration = pipeline::spectral::loadSpectrometerCalibration(
            std::filesystem::path(dir) / config.spectrometerCalibration);
    if (!calibration) {
        return tl::unexpected(calibration.error());
    }
    pipeline::colour::ChannelBasis basis = pipeline::colour::boxBasis();
    std::shared_ptr<const pipeline::spectral::AdaptiveEncoder> encoder;
    if (adaptive) {
        auto made = pipeline::spectral::AdaptiveEncoder::createDefault(dir);
        if (!made) {
            return tl::unexpected(made.error());
        }
        encoder = std::make_shared<const pipeline::spectral::AdaptiveEncoder>(std::move(*made));
        basis = encoder->generalBasis();
    } else if (config.basis != "box6") {
        auto fitted = pipeline::colour::loadChannelBasis(std::filesystem::path(dir) / "channels" /
                                                         (config.basis + ".csv"));
        if (!fitted) {
            return tl::unexpected(fitted.error());
        }
        basis = std::move(*fitted);
    }
    // Surface resolution: about one texel per 2 screen pixels is plenty for flat patches. The
    // booth renderer does not read it (its scene has its own textures).
    auto surface = config.renderer == "flat"
                           ? pipeline::render::makeColorCheckerSurface(dir, basis, 600, 400)
                           : pipeline::render::makeColorCheckerSurface(dir, basis, 6, 4);
    if (!surface) {
        return tl::unexpected(surface.error());
    }

    auto output =
            outputChoice.kind == "kms" ? createKmsOutput(outputChoice.kms) : createHeadlessOutput();
    if (!output) {
        return tl::unexpected(output.error());
    }
    app->output = std::move(*output);
    applyDisplayGeometry(config, *app->output, outputChoice);
    app->config = config;

    pipeline::render::GlesRendererSetup setup;
    setup.stand = config.stand;
    setup.width = config.width;
    setup.height = config.height;
    setup.stand = config.stand;
    setup.booth = app->booth;
    setup.surface = std::move(*surface);
    setup.basis = basis;
    setup.observer = *observer;
    app->displayWhiteXyz = display->model.whiteXyz();
    setup.display = std::move(*display);
    setup.lightsU = config.lightsU;
    setup.lightsV = config.lightsV;
    setup.surroundIlluminance = config.switches.surroundIlluminance;
    if (config.renderer == "booth") {
        auto boothScene = makeBoothScene(app->config, app->booth, basis, *observer, encoder,
                                         setup.display.model);
        if (!boothScene) {
            return tl::unexpected(boothScene.error());
        }
        app->boothScene = *boothScene;
        setup.boothScene = std::move(*boothScene);
    }
    auto renderer = pipeline::render::createGlesRenderer(std::move(setup));
    if (!renderer) {
        return tl::unexpected(renderer.error());
    }
    app->renderer = std::move(*renderer);
    app->displayProfileId = displayId;

    // The state stage (state/): the light, eye and tilt estimators.
    state::SceneEstimatorSetup updaterSetup;
    updaterSetup.light.booth = app->booth;
    updaterSetup.light.calibration = *calibration;
    if (app->boothScene) {
        // The re-encode decision and the diffuse term's sliced refresh are state: the estimators
        // take the booth pass's encoder, lamp spectra and slice count.
        updaterSetup.light.adaptive = encoder;
        updaterSetup.light.encodeSpectra = app->boothScene->lampSpectra();
        updaterSetup.tilt.cacheSlices = config.cacheSlices;
    }
    updaterSetup.eye.trackerInBooth = config.trackerInBooth;
    updaterSetup.eye.defaultEyeM = config.defaultEyeM;
    updaterSetup.tilt.defaultTiltRad = config.defaultTiltRad;
    if (!config.defaultLamp.empty()) {
        const auto& lamps = app->booth.lights;
        const auto it = std::find_if(lamps.begin(), lamps.end(),
                                     [&](const auto& l) { return l.name == config.defaultLamp; });
        if (it == lamps.end()) {
            return makeError(ErrorCode::InvalidArgument,
                             fmt::format("default lamp '{}' is not a lamp of booth '{}' ({})",
                                         config.defaultLamp, config.booth, app->booth.names()));
        }
        updaterSetup.light.defaultLamp = static_cast<int>(it - lamps.begin());
    }
    auto updater = state::SceneEstimator::create(std::move(updaterSetup));
    if (!updater) {
        return tl::unexpected(updater.error());
    }
    app->updater = std::make_unique<state::SceneEstimator>(std::move(*updater));
    return app;
}

Expected<void> restoreStateAtStart(Appliance& appliance, const std::string& configJson)
{
    const auto config = nlohmann::json::parse(configJson, nullptr, false);
    if (config.is_discarded() || !config.is_object() || !config.contains(kStateAtStartKey)) {
        return {};
    }
    if (auto ok = appliance.updater->restore(config[kStateAtStartKey]); !ok) {
        return makeError(ok.error().code, fmt::format("the run configuration's {}: {}",
                                                      kStateAtStartKey, ok.error().message));
    }
    return {};
}

Expected<Sources> makeSimSources(const Appliance& appliance, const std::string& lampSelector)
{
    if (lampSelector != "none" && lampSelector != "sim" && lampSelector != "sim-miswired") {
        return makeError(ErrorCode::InvalidArgument,
                         fmt::format("--lamp-selector {}: expected none, sim or sim-miswired",
                                     lampSelector));
    }
    const std::filesystem::path dir = dataDir();
    hal::sim::ScenarioParams scenario;
    scenario.lampCount = static_cast<int>(appliance.booth.lights.size());

    hal::sim::SimSpectrometerParams spec;
    for (const auto& lamp : appliance.booth.lights) {
        // The simulator sees each lamp at its table's own resolution, not the working grid.
        auto table = pipeline::colour::loadSpectralCsv(dir / "spectra" / lamp.referenceFile);
        if (!table) {
            return tl::unexpected(table.error());
        }
        hal::sim::SimLamp sim{lamp.name, table->wavelengthNm, {}};
        std::size_t column = table->columns.size();
        for (std::size_t c = 0; c < table->columns.size(); ++c) {
            if (table->columns[c] == lamp.referenceColumn) {
                column = c;
            }
        }
        if (column == table->columns.size()) {
            return makeError(ErrorCode::NotFound, fmt::format("{}: no column '{}'", table->source,
                                                              lamp.referenceColumn));
        }
        for (const auto& row : table->rows) {
            sim.power.push_back(row[column]);
        }
        spec.lamps.push_back(std::move(sim));
    }
    auto cal = pipeline::spectral::loadSpectrometerCalibration(
            dir / appliance.config.spectrometerCalibration);
    if (!cal) {
        return tl::unexpected(cal.error());
    }
    spec.responsivityNm = cal->wavelengthNm;
    spec.responsivity = cal->responsivity;

    Sources s;
    s.set(recordings::spectrometerKind(), hal::sim::makeSimSpectrometer(scenario, std::move(spec)));
    s.set(recordings::trackerKind(), hal::sim::makeSimTracker(scenario, {}));
    s.set(recordings::accelKind(), hal::sim::makeSimAccel(scenario, {}));
    if (lampSelector != "none") {
        hal::sim::SimLampSelectorParams selector;
        if (lampSelector == "sim-miswired") {
            selector.wiring = {0, 2, 1};
        }
        s.set(recordings::lampSelectorKind(), hal::sim::makeSimLampSelector(scenario, selector));
    }
    return s;
}

Sources makeReplaySources(const recordings::Recording& recording,
                          const recordings::DeviceKinds& kinds)
{
    Sources s;
    for (const auto* kind : kinds) {
        const auto it = recording.devices.find(kind->name());
        const bool has = it != recording.devices.end() && it->second.has_value();
        const auto& info = recording.session.device(*kind);
        // An optional device the session did not have (no model, no samples) gets no source.
        if (kind->names().optional && info.model.empty() && recording.count(*kind) == 0) {
            continue;
        }
        s.set(*kind, kind->replaySource(info, has ? it->second : kind->emptySamples()));
    }
    return s;
}

} // namespace replica::platform
