// The run configuration: everything that decides what a frame looks like, as JSON (recorded in
// every session) and back.
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
                     {"spectrometer_calibration", spectrometerCalibration},
                     {"display", display},
                     {"display_peak_cd_m2", displayPeakCdM2},
                     {"display_black_cd_m2", displayBlackCdM2},
                     // Without it, a recording is the flat renderer's (readRendering).
                     {"renderer", "booth"},
                     {"scene_dir", sceneDir},
                     {"scene_digest", sceneDigest},
                     {"booth_dir", boothDir},
                     {"booth_digest", boothDigest},
                     {"light", light},
                     {"booth_lights", boothLights},
                     {"specular_samples", specularSamples},
                     {"specular_grid", specularGrid},
                     {"diffuse_grid", diffuseGrid},
                     {"area_lights", areaLights},
                     {"booth_dimmer", boothDimmer},
                     {"booth_dimmer_auto", boothDimmerAuto || boothDimmerChosenAuto},
                     {"cache_slices", cacheSlices},
                     {"tilt_nodes_deg", tiltNodesDeg},
                     {"error_probe_s", errorProbeS},
                     {"render_profile", renderProfile},
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
    j["sensing"] = {{"stray_light", sensing.strayLight},
                    {"wavelength_lines", sensing.wavelengthLines},
                    {"average_spectra", sensing.averageSpectra},
                    {"steady_distance", sensing.steadyDistance},
                    {"stray_light_fraction", instrument.strayLightFraction},
                    {"wavelength_offset_nm", instrument.wavelengthOffsetNm},
                    {"direct_cdm2_per_y", directCdM2PerY}};
    if (!plannedLamps.empty()) {
        nlohmann::json lamps = nlohmann::json::object();
        for (const auto& [name, p] : plannedLamps) {
            lamps[name] = {{"lights", p.lights},
                           {"specular_samples", p.specularSamples},
                           {"horizon_directions", p.horizonDirections},
                           {"walls", p.walls}};
        }
        j["planned_lamps"] = lamps;
    }
    return j.dump();
}

namespace {

// The keys every version records (required by the schema).
void readRequired(const nlohmann::json& j, RunConfig& c)
{
    c.width = j.at("width").get<int>();
    c.height = j.at("height").get<int>();
    c.rateHz = j.at("rate_hz").get<double>();
    c.booth = j.at("booth").get<std::string>();
    c.scene = j.at("scene").get<std::string>();
    c.basis = j.at("basis").get<std::string>();
    c.spectrometerCalibration = j.at("spectrometer_calibration").get<std::string>();
    c.display = j.at("display").get<std::string>();
    c.displayPeakCdM2 = j.at("display_peak_cd_m2").get<double>();
    c.displayBlackCdM2 = j.at("display_black_cd_m2").get<double>();
}

// What the renderers draw with. An absent key is today's default: this build has one render
// path, and a recording of an older render profile replays on it approximately.
void readRendering(const nlohmann::json& j, RunConfig& c)
{
    // Absent in recordings made before the booth renderer: the flat renderer drew them.
    const auto renderer = j.value("renderer", std::string("flat"));
    if (renderer != "booth" && renderer != "flat") {
        throw std::runtime_error(fmt::format("renderer '{}' is not 'booth' or 'flat'", renderer));
    }
    c.drawnByFlatRenderer = renderer == "flat";
    c.sceneDir = j.value("scene_dir", c.sceneDir);
    c.sceneDigest = j.value("scene_digest", c.sceneDigest);
    if (c.drawnByFlatRenderer) {
        // The flat renderer drew its built-in ColorChecker whatever scene the run named: the
        // booth pass draws the shipped ColorChecker scene in its place.
        c.sceneDir = RunConfig{}.sceneDir;
        c.sceneDigest.clear();
    }
    // Absent before a booth could be named: the shipped one, undigested; and the classifier's
    // light ("auto").
    c.boothDir = j.value("booth_dir", c.boothDir);
    c.boothDigest = j.value("booth_digest", c.boothDigest);
    c.light = j.value("light", std::string(kLightAuto));
    c.boothLights = j.value("booth_lights", c.boothLights);
    c.specularSamples = j.value("specular_samples", c.specularSamples);
    c.specularGrid = j.value("specular_grid", c.specularGrid);
    c.diffuseGrid = j.value("diffuse_grid", c.diffuseGrid);
    c.areaLights = j.value("area_lights", c.areaLights);
    // A recorded "auto" is the number it chose; a replay never chooses again.
    c.boothDimmer = j.value("booth_dimmer", c.boothDimmer);
    c.boothDimmerChosenAuto = j.value("booth_dimmer_auto", false);
    c.cacheSlices = j.value("cache_slices", c.cacheSlices);
    // Absent in recordings made before tilt nodes: the held tilt's term, as they were drawn.
    c.tiltNodesDeg = j.value("tilt_nodes_deg", 0.0);
    c.errorProbeS = j.value("error_probe_s", c.errorProbeS);
    c.renderProfile = j.value("render_profile", 0);
    c.horizonDirections = j.value("horizon_directions", c.horizonDirections);
    c.displayDigest = j.value("display_digest", c.displayDigest);
    c.displayInverse = j.value("display_inverse", c.displayInverse);
    c.gamutMapping = j.value("gamut_mapping", c.gamutMapping);
    c.viewingCompensation = j.value("viewing_compensation", c.viewingCompensation);
    c.flareSubtraction = j.value("flare_subtraction", c.flareSubtraction);
    c.falseColour = j.value("false_colour", c.falseColour);
    if (j.contains("planned_lamps")) {
        for (const auto& [name, l] : j.at("planned_lamps").items()) {
            LampPlan p;
            p.lights = l.at("lights").get<int>();
            p.specularSamples = l.at("specular_samples").get<int>();
            p.horizonDirections = l.at("horizon_directions").get<int>();
            p.walls = l.value("walls", true); // absent: recorded before the planner chose walls
            if (p.lights < 1 || p.lights > 256 || p.specularSamples < 0 ||
                p.specularSamples > 256 || p.horizonDirections < 0 || p.horizonDirections > 32) {
                throw std::runtime_error(
                        fmt::format("planned_lamps.{}: a count out of range", name));
            }
            c.plannedLamps[name] = p;
        }
    }
}

// "key": [x, y, z] into v when present.
void readVec3(const nlohmann::json& j, const char* key, glm::dvec3& v)
{
    if (j.contains(key)) {
        const auto a = j.at(key).get<std::vector<double>>();
        if (a.size() != 3) {
            throw std::runtime_error(fmt::format("{}: expected 3 numbers", key));
        }
        v = {a[0], a[1], a[2]};
    }
}

// The stand, the panel, the tracker's mounting and the defaults for absent samples.
Expected<void> readGeometry(const nlohmann::json& j, RunConfig& c)
{
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
    } else if (j.contains("tracker_rotation_deg") || j.contains("tracker_translation_m")) {
        // Recordings made before the transform was recorded whole hold the site file's angles
        // (degrees) and translation.
        glm::dvec3 rotationDeg{0.0};
        glm::dvec3 translationM = pipeline::kDefaultTrackerInBoothM;
        readVec3(j, "tracker_rotation_deg", rotationDeg);
        readVec3(j, "tracker_translation_m", translationM);
        c.trackerInBooth = pipeline::rigidFromDegrees(rotationDeg, translationM);
    }
    readVec3(j, "stand_hinge_m", c.stand.hingeM);
    c.stand.hingeToPanelM = j.value("stand_hinge_to_panel_m", c.stand.hingeToPanelM);
    c.stand.panelWidthM = j.value("panel_width_m", c.stand.panelWidthM);
    c.stand.panelHeightM = j.value("panel_height_m", c.stand.panelHeightM);
    c.defaultLamp = j.value("default_lamp", c.defaultLamp);
    readVec3(j, "default_eye_m", c.defaultEyeM);
    c.defaultTiltRad = j.value("default_tilt_rad", c.defaultTiltRad);
    return {};
}

// The live spectrometer chain's options and the instrument's calibration. Absent before the
// live chain's corrections: none, one spectrum at a time.
void readSensing(const nlohmann::json& j, RunConfig& c)
{
    c.sensing = pipeline::spectral::LiveChainOptions::none();
    c.instrument = {};
    // Absent before direct-sensor mode followed the reading: the booth's mean luminance.
    c.directCdM2PerY = 0.0;
    if (j.contains("sensing")) {
        const auto& s = j.at("sensing");
        c.sensing.strayLight = s.at("stray_light").get<bool>();
        c.sensing.wavelengthLines = s.at("wavelength_lines").get<bool>();
        c.sensing.averageSpectra = s.at("average_spectra").get<int>();
        c.sensing.steadyDistance = s.at("steady_distance").get<double>();
        c.instrument.strayLightFraction = s.at("stray_light_fraction").get<double>();
        c.instrument.wavelengthOffsetNm = s.at("wavelength_offset_nm").get<double>();
        c.directCdM2PerY = s.value("direct_cdm2_per_y", 0.0);
    }
}

// The checks across fields and ranges the schema cannot state.
Expected<void> checkRanges(const RunConfig& c)
{
    if (!frameSizeOk(c.width, c.height) || !(c.rateHz >= 1.0) || c.rateHz > 1000.0 ||
        !std::isfinite(c.displayPeakCdM2) || !std::isfinite(c.displayBlackCdM2) ||
        c.boothLights < 1 || c.boothLights > 256 || c.specularSamples < kAutoSpecularSamples ||
        c.specularSamples > 256 || c.horizonDirections < 0 || c.horizonDirections > 32 ||
        c.specularGrid < kAutoSpecularGrid || c.specularGrid > 256 ||
        c.diffuseGrid < kAutoDiffuseGrid || c.diffuseGrid > 256 || c.cacheSlices < 1 ||
        c.cacheSlices > kMaxCacheSlices || !(c.tiltNodesDeg >= 0.0) ||
        c.tiltNodesDeg > kMaxTiltNodesDeg || c.areaLights < kAutoAreaLights || c.areaLights > 1 ||
        !(c.boothDimmer > 0.0) || c.boothDimmer > 1.0 || !(c.directCdM2PerY >= 0.0) ||
        c.directCdM2PerY > 1e12) {
        return makeError(ErrorCode::InvalidArgument,
                         fmt::format("run configuration: size {}x{} (each side 1-{}, at most "
                                     "{}:1), rate {} Hz (1-1000), display peak/black, specular "
                                     "samples, specular or diffuse grid, horizon directions, "
                                     "cache slices, tilt nodes (0 to 10 degrees), area lights, "
                                     "booth dimmer (0 to 1) or "
                                     "direct_cdm2_per_y out of range",
                                     c.width, c.height, kMaxFrameSide, kMaxFrameAspect, c.rateHz));
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
    return {};
}

// The names fromJson takes for the display inverse and the gamut mapping.
Expected<void> checkNames(const RunConfig& c)
{
    if (c.light != kLightAuto && c.light != kLightDirect) {
        return makeError(ErrorCode::InvalidArgument,
                         fmt::format("run configuration: light '{}' is not '{}' or '{}'",
                                     c.light.substr(0, 64), kLightAuto, kLightDirect));
    }
    if ((c.displayInverse != "analytic" && c.displayInverse != "lut3d") ||
        (c.gamutMapping != "hue" && c.gamutMapping != "clip")) {
        return makeError(ErrorCode::InvalidArgument,
                         fmt::format("run configuration: display inverse '{}' (analytic, lut3d) "
                                     "or gamut mapping '{}' (hue, clip) unknown",
                                     c.displayInverse, c.gamutMapping));
    }
    if (auto ok = pipeline::render::checkRenderProfile(c.renderProfile); !ok) {
        return makeError(ErrorCode::Unsupported,
                         fmt::format("run configuration: {}", ok.error().message));
    }
    return {};
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
        readRequired(j, c);
        readRendering(j, c);
        readSensing(j, c);
        if (auto ok = readGeometry(j, c); !ok) {
            return tl::unexpected(ok.error());
        }
    } catch (const std::exception& e) {
        return makeError(ErrorCode::Corrupt, fmt::format("run configuration: {}", e.what()));
    }
    if (auto ok = checkRanges(c); !ok) {
        return tl::unexpected(ok.error());
    }
    if (auto ok = checkNames(c); !ok) {
        return tl::unexpected(ok.error());
    }
    return c;
}

} // namespace replica::platform
