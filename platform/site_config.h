// The site file (/etc/replica/replica.toml): what one installation is — its booth, scene, display,
// stand and tracker geometry, devices, rate, recording policy, log levels and the scene shown
// while a sensor is missing. 'replica run --config FILE' reads it (the command line overrides
// it); 'replica config check FILE' reports every problem with its key and line.
#pragma once

#include <cstdint>
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <glm/vec3.hpp>

#include <pipeline/base/expected.h>
#include <pipeline/base/rigid_transform.h>
#include <pipeline/scene/stand.h>

namespace replica::platform {

// The compiled-in default of the site file: REPLICA_SITE_CONFIG (/etc/replica/replica.toml).
std::filesystem::path defaultSiteConfigPath();

// The stand a site file takes: the hinge within this of the booth's origin on each axis, the
// panel's bottom edge within this of the hinge (metres; a booth is about a metre across).
constexpr double kStandHingeLimitM = 5.0;
constexpr double kStandHingeToPanelLimitM = 1.0;

// Every value has the default a run without a site file has, so that a file holding only some
// keys changes only those (and recordings made without one are unchanged).
struct SiteConfig {
    std::filesystem::path source; // the file read; empty: built-in defaults

    // [booth]
    std::string boothId = "replica-booth-1";
    // dimmer = <number in (0, 1]> | "auto" (platform/booth_dimmer.h); absent: 1, undimmed.
    double boothDimmer = 1.0;
    bool boothDimmerAuto = false;
    // dir = the booth model's folder ('replica booth build' writes one from a site's captures;
    // under the data folder or absolute); empty: the shipped booth (data/booth).
    std::string boothDir;
    // light = "auto" (the classifier's lamp, the sensed spectrum where none matches) | "direct"
    // (always the sensed spectrum: direct-sensor mode, 'replica run --light direct').
    std::string light = "auto";
    // [spectrometer]: the instrument's calibration ('replica calibrate spectrometer';
    // pipeline/spectral/live_chain.h InstrumentCalibration): absent, the data sheet's stray light
    // and no shift.
    double spectrometerStrayLight = 5e-4;
    double spectrometerWavelengthOffsetNm = 0.0;
    // direct_cdm2_per_y: direct-sensor mode's level, the emitter's luminance per unit of the
    // reading's Y (RunConfig::directCdM2PerY); absent: the simulated instrument's.
    std::optional<double> spectrometerDirectCdM2PerY;
    // [scene]
    std::string sceneDir;           // empty: the default scene (data/scenes/colorchecker)
    std::string renderer = "booth"; // the one renderer; "flat" is read to be refused by name
    // [render] planner = true: the planner in the loop (RunConfig::planner), planning a scene
    // that has no plan yet at start; false: the fixed rules; absent (renderPlannerSet false):
    // 'replica run''s default, the plan when the scene has one (cached or shipped).
    bool renderPlanner = false;
    bool renderPlannerSet = false;
    // [render] warm_up = false: 'replica run --no-warm-up' (RunConfig::warmUp).
    bool warmUp = true;
    // [render] error_probe = seconds between the error probes, 0: none ('replica run
    // --error-probe'; platform/loop/error_probe.h). Absent: every 10 s (kKioskErrorProbeS).
    double errorProbeS = 10.0;
    // [display]
    std::string displayProfile;   // empty: the shipped synthetic profile
    bool allowSynthetic = false;  // the kiosk refuses a live run on the synthetic profile
    std::string output = "kms";   // "kms" or "headless"
    std::string size = "960x600"; // the frame size WIDTHxHEIGHT
    std::string kmsDevice = "/dev/dri/card0";
    std::string kmsConnector; // empty: the first connected
    // [stand] (pipeline/scene/stand.h): defaults are the compiled-in model.
    pipeline::scene::StandModel stand;
    // [tracker]: T_booth_tracker, the tracker's pose in the booth, as the file spells it: angles
    // about x, then y, then z (degrees) and a translation, or the calibrated T_booth_tracker
    // matrix ('replica calibrate tracker'), which wins when present. trackerInBooth() is the
    // one transform the run uses.
    glm::dvec3 trackerRotationDeg{0.0};
    glm::dvec3 trackerTranslationM = pipeline::kDefaultTrackerInBoothM;
    std::optional<pipeline::RigidTransform> trackerCalibrated;
    pipeline::RigidTransform trackerInBooth() const
    {
        return trackerCalibrated
                       ? *trackerCalibrated
                       : pipeline::rigidFromDegrees(trackerRotationDeg, trackerTranslationM);
    }
    std::uint16_t trackerPort = 4242;
    std::string trackerBind = "127.0.0.1";
    // [devices]
    std::string iioRoot = "/sys/bus/iio/devices";
    std::string accelName;
    std::string accelAxes = "x,y,z";
    std::string lampGpio;
    std::string spectrometerSerial; // the USB2000+'s USB serial number; empty: the first found
    // [run]
    std::string hal = "live"; // live, sim or replay
    std::string replayFile;   // hal = "replay": the recording whose samples feed the display
    double rateHz = 60.0;
    double minRateHz = 15.0; // the steady cadence's lowest rate (platform/loop/cadence.h)
    // [recording]
    bool recordingEnabled = true;
    std::string recordingDirectory = "/var/lib/replica/sessions";
    std::uint64_t rotateBytes = 256ull << 20; // a new session file after this many bytes (recovered
                                              // at start in about 4.1 x that: replica.service)
    std::uint64_t rotateSeconds = 3600;       // or after this long
    std::uint64_t keepBytes = 20ull << 30;    // the oldest sessions go beyond this total
    int flushMs = 500;
    // [log]
    std::string logLevel = "info";
    // [defaults]: the scene shown before (or without) each sensor's first sample.
    std::string defaultLamp; // a booth lamp's name; empty: black until the first spectrum
    glm::dvec3 defaultEyeM{0.0, 0.45, 0.60};
    double defaultTiltDeg = 0.0;

    // The line of each key the file gives ("display.size" -> 12), for problems found when the
    // values are resolved (platform/cli/run_resolve.h).
    std::map<std::string, long> lines;
    long lineOf(const std::string& key) const
    {
        const auto it = lines.find(key);
        return it != lines.end() ? it->second : 0;
    }

    // The resolved configuration as JSON (recorded in each session).
    std::string toJson() const;
};

struct SiteProblem {
    std::string key; // "display.size"
    long line = 0;   // 0: not tied to a line
    std::string what;
};

struct SiteLoad {
    SiteConfig config;
    std::vector<SiteProblem> problems; // empty: the file is good
};

// Reads and checks a site file: every unknown key, wrong type, out-of-range or non-finite value
// is a problem (the values that are good are kept). Fails only when the file cannot be read or
// is not TOML at all (the error names the line).
Expected<SiteLoad> loadSiteConfig(const std::filesystem::path& file);
// The same for the text of 'file' already read (the fuzz target, tests/fuzz/site_file_fuzz.cpp).
Expected<SiteLoad> parseSiteConfig(const std::string& text, const std::filesystem::path& file);

// "FILE:LINE: key: what" (LINE left out when 0).
std::string formatProblem(const std::filesystem::path& file, const SiteProblem& p);

} // namespace replica::platform
