// Builds the appliance's parts from a run configuration: output (GL context), renderer, scene
// estimator (the state stage), and the HAL sources (simulated or replayed).
#pragma once

#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <glm/vec3.hpp>
#include <state/scene_estimator.h>

#include <hal/sim/sim_devices.h>
#include <hal/sources.h>
#include <pipeline/base/expected.h>
#include <pipeline/base/rigid_transform.h>
#include <pipeline/display/display_model.h>
#include <pipeline/render/booth_scene_pass.h>
#include <pipeline/render/render_profile.h>
#include <pipeline/render/renderer.h>
#include <pipeline/scene/calibration.h>
#include <pipeline/scene/stand.h>
#include <pipeline/spectral/live_chain.h>
#include <platform/output/output.h>
#include <platform/render_plan.h>
#include <recordings/recording.h>

namespace replica::platform {

// RunConfig::specularGrid, diffuseGrid and specularSamples: chosen for the scene when the
// appliance is built.
constexpr int kAutoSpecularGrid = -1;
constexpr int kAutoDiffuseGrid = -1;
constexpr int kAutoSpecularSamples = -1;
constexpr int kAutoAreaLights = -1;
// RunConfig::cacheSlices for new runs (docs/rendering.md measures the choice), and the most a
// configuration may ask for.
constexpr int kDefaultCacheSlices = 3;
constexpr int kMaxCacheSlices = 16;
// RunConfig::tiltNodesDeg for new runs (docs/rendering.md, "Tilt nodes", measures the choice),
// and the most a recording may ask for.
constexpr double kDefaultTiltNodesDeg = 2.0;
constexpr double kMaxTiltNodesDeg = 10.0;
// Frame sizes a run takes and a recording may hold: each side 1..8192 pixels and at most 16:1
// (a 16384x1 "frame" is no display).
constexpr int kMaxFrameSide = 8192;
constexpr int kMaxFrameAspect = 16;
inline bool frameSizeOk(long long w, long long h)
{
    return w > 0 && h > 0 && w <= kMaxFrameSide && h <= kMaxFrameSide && w <= kMaxFrameAspect * h &&
           h <= kMaxFrameAspect * w;
}

// RunConfig::light: the classifier's booth lamp, the sensed spectrum where none matches (the
// default), or always the sensed spectrum (the paper's mode 1, direct-sensor mode).
constexpr const char* kLightAuto = "auto";
constexpr const char* kLightDirect = "direct";
// RunConfig::directCdM2PerY for new runs: the simulated spectrometer's calibration, so that its
// reading of the shipped tungsten lamp renders at that lamp's nominal luminance (2200 cd/m^2;
// checked by tests/unit/state/direct_sensor_test.cpp). A real instrument's is the site file's
// [spectrometer] direct_cdm2_per_y.
constexpr double kDefaultDirectCdM2PerY = 7.3451e-5;

// Everything that decides what a frame looks like, apart from the samples. Recorded in the session
// so that replay rebuilds the identical renderer.
struct RunConfig {
    int width = 960;
    int height = 600;
    double rateHz = 60.0;
    std::string booth = "replica-booth-1";
    std::string scene = "colorchecker";
    // A recording drawn by the flat renderer, which this build does not have (its "renderer" is
    // "flat", or it has no such key: it was made before the booth renderer). Replay draws it with
    // the booth pass like any other and compares the frames with what the recording showed, as
    // for an older render profile. A new run records "renderer": "booth".
    bool drawnByFlatRenderer = false;
    std::string sceneDir = "scenes/colorchecker"; // relative paths are under the data folder
    std::string sceneDigest; // FNV-1a 64 of the scene's files; replay refuses a changed scene
    // The booth model's folder (booth.json and each light's luminance EXR, as 'replica booth
    // build' writes it; relative paths are under the data folder) and the digest of its files
    // (platform::boothDigest). Replay refuses a booth whose files have changed. Recordings made
    // before have neither: the shipped booth, unchecked.
    std::string boothDir = "booth";
    std::string boothDigest;
    // kLightAuto or kLightDirect (direct-sensor mode forced). Recordings made before: auto.
    std::string light = kLightAuto;
    // Direct-sensor mode's level (state::LightEstimatorSetup::directCdM2PerY): the emitter's
    // luminance per unit of the reading's Y, recorded in "sensing". Recordings made before have
    // none and replay with 0 (the booth's mean luminance), frame for frame.
    double directCdM2PerY = kDefaultDirectCdM2PerY;
    int boothLights = 32; // median-cut point lights
    // Specular samples per pixel or grid node; kAutoSpecularSamples: shading::
    // defaultSpecularSamples for the scene (8 on relief, 24 on a flat surface), chosen when the
    // appliance is built and recorded as chosen. Recordings made before hold the count they used.
    int specularSamples = kAutoSpecularSamples;
    // Texels between the specular grid's nodes (shading::RenderSettings::specularGrid); 0: per
    // pixel; kAutoSpecularGrid: shading::defaultSpecularGrid for the scene, chosen when the
    // appliance is built and recorded as chosen.
    // Recordings made before the grid have none: they replay per pixel.
    int specularGrid = kAutoSpecularGrid;
    // Texels between the diffuse grid's nodes (shading::RenderSettings::diffuseGrid; flat
    // surfaces only); 0: per pixel; kAutoDiffuseGrid: shading::defaultDiffuseGrid for the scene,
    // chosen when the appliance is built and recorded as chosen. Recordings made before the grid
    // have none: they replay per pixel.
    int diffuseGrid = kAutoDiffuseGrid;
    int horizonDirections = 8;
    // The render path that drew the frames (pipeline/render/render_profile.h): a new run's is
    // kRenderProfile; a recording's is the number it holds (0 without the key). Only
    // kRenderProfile is rendered; an older number marks a recording whose frames this build
    // reproduces approximately (replay compares them with what the recording showed).
    int renderProfile = pipeline::render::kRenderProfile;
    // shading::RenderSettings::areaLights: 1 eq. (1) from the median-cut regions' areas, 0 from
    // point lights; kAutoAreaLights: shading::defaultAreaLights for the scene (areas on a flat
    // surface, points on relief), chosen when the appliance is built and recorded as chosen.
    // Recordings made before it have none and replay with point lights, bit for bit.
    int areaLights = kAutoAreaLights;
    // The booth dimmer (platform/booth_dimmer.h): every booth light's luminance times this, in
    // (0, 1]. boothDimmerAuto asks buildAppliance to choose it for the scene and the display
    // (the site's [booth] dimmer = "auto"); the number chosen is recorded with
    // boothDimmerChosenAuto set. Recordings made before it have none and replay at 1, bit for
    // bit.
    double boothDimmer = 1.0;
    bool boothDimmerAuto = false;
    bool boothDimmerChosenAuto = false;
    // shading::RenderSettings::cacheSlices: a tilt recomputes the cached diffuse term in this many
    // bands over as many frames. Recordings made before it have none and replay with 1 (whole at
    // once), frame for frame.
    int cacheSlices = kDefaultCacheSlices;
    // shading::RenderSettings::tiltNodesRad, in degrees: the diffuse term cached at tilt nodes
    // this far apart and interpolated between them (0: the held tilt's term alone). Recordings
    // made before it have none and replay with 0, frame for frame.
    double tiltNodesDeg = kDefaultTiltNodesDeg;
    // The planner in the loop (platform/render_plan.h). planner asks buildAppliance for the
    // cached plan of the scene (computed once when missing; plannerCache empty: the default cache
    // folder); the per-lamp choice it takes is recorded as plannedLamps ("planned_lamps"), and a
    // lamp there draws with its own lights, specular samples and horizon directions. Recordings
    // made before have none and replay with the fixed rules above, bit for bit; a replay never
    // plans again. Where the plan comes from: the cache folder, else the one shipped in the scene
    // folder (same file name), else, with planIfMissing, computed now (minutes); without it (what
    // 'replica run' asks when neither --planner, --no-planner nor the site's [render] planner
    // says) a scene with no plan draws with the fixed rules and a log line says how to plan it.
    bool planner = false;
    bool planIfMissing = true;
    std::string plannerCache;
    // Not recorded (no pixel depends on it): draw every lamp's shading pass once at start
    // (BoothScenePass::warmUp) so that no lamp switch waits for a shader compilation.
    bool warmUp = true;
    // Not recorded: with warmUp, compile before the first frame only the pass that frame draws
    // and the others after it (platform/output/pass_warm_up.h: a thread of its own, then the loop's
    // idle time); what 'replica run' does. Off (replay, the benchmarks): every pass before the
    // loop.
    bool warmUpAfterFirstFrame = false;
    // Seconds of session time between the running appliance's error probes, 0: none
    // (platform/loop/error_probe.h). Recorded ("error_probe_s") to say what the session measured;
    // no pixel depends on it and a replay never probes. Recordings made before have none.
    double errorProbeS = 0.0;
    std::map<std::string, LampPlan> plannedLamps;
    // docs/accuracy.md. adaptive_k6 re-encodes the surface for each new light; recordings made
    // with replica_k6 or box6 replay as such.
    std::string basis = "adaptive_k6";
    std::string spectrometerCalibration = "spectrometer/sim_usb2000_responsivity.csv";
    // The live spectrometer chain (pipeline/spectral/live_chain.h): its corrections and averaging,
    // and the instrument's calibration (stray light, wavelength shift) they use, recorded as
    // "sensing". Recordings made before it have none and replay with LiveChainOptions::none()
    // (countsToSpectrum with default options, one spectrum at a time), spectrum for spectrum.
    pipeline::spectral::LiveChainOptions sensing;
    pipeline::spectral::InstrumentCalibration instrument;
    // The display profile: a path under data/ (or absolute), or kUncalibratedDisplay for the
    // nominal sRGB-like model of displayPeakCdM2/displayBlackCdM2 ('replica run --uncalibrated';
    // also what recordings made before profiles existed replay with).
    std::string display = "displays/wide-ips-synthetic.json";
    std::string displayDigest; // FNV-1a 64 of the profile file, hex; checked again on replay
    double displayPeakCdM2 = 800.0;
    double displayBlackCdM2 = 0.4;
    std::string displayInverse = "analytic"; // or "lut3d" (docs/display.md compares them)
    std::string gamutMapping = "hue";        // or "clip" (per channel, for comparison only)
    bool viewingCompensation = true;
    bool flareSubtraction = true;
    bool falseColour = false;
    // The site's geometry (the site file's [stand] and [tracker]): the stand's hinge and the
    // panel's physical size, and T_booth_tracker (eye_booth = trackerInBooth.apply(eye_tracker)):
    // 'replica run --site' takes it from the site file, calibrated ('replica calibrate tracker')
    // or as angles and a translation. Recorded as t_booth_tracker (a rotation matrix and a
    // translation); recordings made before hold the angles in degrees or nothing, and replay with
    // what those give (nothing: the fixed mounting, pipeline::defaultTrackerInBooth()).
    pipeline::scene::StandModel stand;
    pipeline::RigidTransform trackerInBooth = pipeline::defaultTrackerInBooth();
    // The scene before each sensor's first sample (the site file's [defaults]): the lamp shown
    // until the first spectrum (a booth lamp's name; empty: no light, black, as recordings made
    // before have), the eye until the first pose, the tilt until the first gravity sample.
    std::string defaultLamp;
    glm::dvec3 defaultEyeM{0.0, 0.45, 0.60};
    double defaultTiltRad = 0.0;

    std::int64_t periodNs() const;
    std::string toJson() const;
    // A recording's configuration is untrusted: it is held against runConfigSchema() first
    // (run_config_schema.h), naming the JSON path of a refused value; unknown keys go to
    // 'warnings' when given, else to jsonWarningSink().
    static Expected<RunConfig> fromJson(const std::string& json,
                                        std::vector<std::string>* warnings = nullptr);
};

// The light-adaptive basis (pipeline/spectral/adaptive_encoding.h): the default for new runs.
constexpr const char* kAdaptiveBasis = "adaptive_k6";

constexpr const char* kUncalibratedDisplay = "srgb-like-800";

// What a recording's session names the display by: the profile's name and file digest, or the
// nominal model's name marked uncalibrated.
std::string displayProfileId(const RunConfig& config, const std::string& profileName);

// What to say when the display profile a run names is not there: how to make one, or how to run
// without. The appliance and the configuration check give the same advice.
std::string missingDisplayProfileMessage(const std::string& path);

// The run's sources, one per device kind present (recordings/device_kind.h); a booth without a
// lamp selector has none.
using recordings::Sources;

struct Appliance {
    RunConfig config;
    pipeline::booth::Booth booth; // scene::loadDefaultBooth: its lights are the lamps
    std::unique_ptr<Output>
            output; // owns the GL context: created before, destroyed after the renderer
    std::unique_ptr<pipeline::render::Renderer> renderer;
    // The renderer's pass 1 (shared with the renderer): what tests ask about the adaptive
    // encoding (its basis, how often it re-encoded).
    std::shared_ptr<pipeline::render::BoothScenePass> boothScene;
    std::unique_ptr<state::SceneEstimator> sceneEstimator; // the state stage (state/)
    std::string displayProfileId;                          // as recorded in the session
    glm::dvec3 displayWhiteXyz{0.0}; // the panel's full white (cd/m^2): Lab white of frame reports
    pipeline::display::DisplayModel displayModel; // the panel: drive values to XYZ (replay)
    ~Appliance()
    {
        boothScene.reset();
        renderer.reset(); // GL objects go while the context still exists
        output.reset();
    }
};

// The scene folder a configuration names (relative: under the data folder), and the digest of the
// files that make the scene (scene.json, channels.exr, height.exr, material.exr).
std::filesystem::path resolveSceneDir(const std::string& sceneDir);
Expected<std::string> sceneDigest(const std::filesystem::path& dir);

// What every file a recording names (scene, booth, display profile) goes through: the digest of
// the file as it is now must equal the one recorded (when one was), and becomes the recorded one.
// 'what' names the file's kind and 'where' its path in the error ("the booth has changed ...").
Expected<void> checkAndRecordDigest(std::string& recorded,
                                    const std::string& now,
                                    std::string_view what,
                                    const std::string& where);

// The booth the configuration names (boothDir, relative: under the data folder), its digest
// checked against the recorded one (boothDigest; refused when it differs) and then recorded.
Expected<pipeline::booth::Booth> loadRunBooth(RunConfig& config);

// A recording is untrusted: before replay builds anything from its configuration, the files it
// names (scene folder, display profile, spectrometer calibration) must lie inside the data folder
// or one of 'roots' (relative names without '..', or absolute paths inside a root), and the scene
// and display digests (and the booth's, when the recording names a booth folder) must be recorded
// unless 'allowUndigested'. The error names the key and the fix.
Expected<void> checkRecordedReferences(const RunConfig& config,
                                       const std::vector<std::filesystem::path>& roots,
                                       bool allowUndigested);

// The booth renderer's settings as the configuration records them. The scene's counts must
// already be chosen (specular samples and the two grids not kAuto*: makeBoothScene chooses and
// records them); a replay gets the settings its recording ran with.
pipeline::shading::RenderSettings boothRenderSettings(const RunConfig& config);

// Where frames go; not part of RunConfig because it never changes what a frame looks like (what
// it decides of the frame, its size and panel, goes into the RunConfig as built).
struct OutputChoice {
    std::string kind = "headless"; // or "kms"
    KmsOptions kms;
    // KMS: the frame takes the mode's size (a run; a replay keeps its recording's size).
    bool frameFromMode = false;
    // KMS: the panel's size comes from the display's EDID (a run with no configured size).
    bool panelFromDisplay = false;
};

// Creates the output and everything that renders. Fails with a one-line reason. With the booth
// renderer, config.sceneDigest (when not empty) must match the scene on disk.
Expected<std::unique_ptr<Appliance>> buildAppliance(const RunConfig& config,
                                                    const OutputChoice& output = {});

// The run configuration's key for the estimators' state at the start of a rotated session file
// (state::SceneEstimator::save), which files 2, 3, ... of a kiosk session carry so that each
// replays alone; absent in the first file and in every recording made before.
constexpr const char* kStateAtStartKey = "state_at_start";
// Restores the appliance's estimators from a recording's configuration JSON when it has
// kStateAtStartKey; nothing to do otherwise. Fails with one line naming what is wrong.
Expected<void> restoreStateAtStart(Appliance& appliance, const std::string& configJson);

// The booth's lamps as the simulated spectrometer sees them: each lamp's reference column at its
// table's own resolution, not the working grid; fails naming a missing file or column.
Expected<std::vector<hal::sim::SimLamp>> simLamps(const pipeline::booth::Booth& booth);

// The built-in simulated sensors playing the scripted scenario. lampSelector: "none", "sim" (a
// switch that follows the scenario's lamps), or "sim-miswired" (its lines for lamps 1 and 2
// swapped, to exercise the disagreement path).
Expected<Sources> makeSimSources(const Appliance& appliance,
                                 const std::string& lampSelector = "none");

// Sources that return exactly what the recording holds, one per device kind it has (an optional
// kind only when the session had it).
Sources makeReplaySources(const recordings::Recording& recording,
                          const recordings::DeviceKinds& kinds = recordings::deviceKinds());

} // namespace replica::platform
