// The options of 'replica run': what the command line and the site file give, and how the site
// file fills in what the command line leaves open.
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <utility>

#include <CLI/CLI.hpp>

#include <platform/appliance.h>
#include <platform/live_sources.h>
#include <platform/site_config.h>
#include <recordings/device_kind.h>

namespace replica::platform::run_cli {

struct RunOptions {
    std::string hal = "sim";
    // Per device kind name (recordings::deviceKinds()), its source: --spectrometer, --tracker,
    // --accel, --lamp-selector (DeviceNames::sources; absent or empty: follow --hal).
    std::map<std::string, std::string> sources;
    std::string replayFrom; // the recording that devices set to 'replay' play back
    std::string sitePath;   // --site: [sources] and [tracker] T_booth_tracker (calibrate)
    std::string output = "headless";
    std::uint64_t frames = 180;
    std::string size; // headless: 960x600 when not given; kms: the mode's size
    std::string panelSizeMm;
    double rateHz = 60.0;
    double minRateHz = 15.0; // --min-rate: the steady cadence's lowest rate (loop/cadence.h)
    std::string record;
    bool force = false; // --force: overwrite an existing recording
    int recordFlushMs = 500;
    std::string digests;
    std::string snapshot;
    bool fast = false;
    std::string scene;
    std::string booth;          // --booth: the booth model's folder; empty: the shipped one
    std::string light = "auto"; // --light: auto or direct (direct-sensor mode)
    std::string renderer = "booth";
    std::string basis; // empty: adaptive_k6
    std::string displayProfile;
    bool uncalibrated = false;
    std::string displayInverse = "analytic";
    std::string gamut = "hue";
    bool noViewing = false;
    bool noFlare = false;
    bool falseColour = false;
    bool planner = false;   // --planner: plan a scene that has no plan yet
    bool noPlanner = false; // --no-planner: the fixed rules
    std::string planCache;
    bool noWarmUp = false;     // --no-warm-up: RunConfig::warmUp false
    bool recordDigests = true; // format 4: XXH3-64 of every displayed frame in the recording
    double thumbnailHz = 1.0;
    double errorProbeS = 0.0; // --error-probe: seconds between error probes, 0: none
    double tiltNodesDeg = kDefaultTiltNodesDeg; // --tilt-nodes: RunConfig::tiltNodesDeg
    int thumbnailWidth = 320;
    bool json = false;
    LiveOptions live;
    OutputChoice outputChoice;
    std::string replayFile; // --hal replay
    std::string config;     // the site file
    bool kiosk = false;
    std::string faults; // --inject-faults
    // From the site file only (no command-line option).
    std::optional<SiteConfig> site;
    // The options the command line gave ("--size"): the site file fills in the others.
    std::set<std::string> given;
    bool logLevelGiven = false; // --log-level or $REPLICA_LOG: the site's [log] level is not used
};

constexpr int kExitConfig = 78; // EX_CONFIG: the unit's RestartPreventExitStatus

// Declares every option of 'replica run' on 'cmd', each into its field of 'o'.
void addRunOptions(CLI::App& cmd, RunOptions& o);

// The options 'cmd' was given on the command line, for RunOptions::given.
std::set<std::string> givenOptions(const CLI::App& cmd);

// The site file's values for every option the command line did not give (o.given).
void applySite(const SiteConfig& s, RunOptions& o);

// The run's option that chooses a device kind's source, without its dashes: "spectrometer",
// "lamp-selector".
std::string deviceOption(const recordings::DeviceKindBase& kind);

// A file name relative to the data folder (absolute ones as they are).
std::string dataPath(const std::string& p);

// "WIDTHxHEIGHT" within frameSizeOk, or nothing.
std::optional<std::pair<int, int>> parseSize(const std::string& s);

} // namespace replica::platform::run_cli
