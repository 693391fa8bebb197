// 'replica run': the appliance's main job, the fixed-rate loop on the chosen sensors and output.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <iterator>
#include <map>
#include <numbers>
#include <optional>
#include <utility>

#include <fmt/format.h>
#include <nlohmann/json.hpp>
#include <sys/stat.h>

#include <pipeline/base/data_dir.h>
#include <pipeline/spectral/representation_catalogue.h>
#include <platform/appliance.h>
#include <platform/cli/commands.h>
#include <platform/cli/frame_outputs.h>
#include <platform/fault_injection.h>
#include <platform/live_sources.h>
#include <platform/logging.h>
#include <platform/loop/frame_loop.h>
#include <platform/loop/shown_recorder.h>
#include <platform/session_files.h>
#include <platform/site_config.h>
#include <platform/site_file.h>
#include <platform/systemd_notify.h>
#include <platform/version.h>
#include <recordings/recording.h>

namespace replica::platform {
namespace {

struct RunOptions {
    std::string hal = "sim";
    // Per device (empty: follow --hal): spectrometer live|sim|replay, tracker opentrack|hid|sim|
    // replay, accel live|sim|replay, lamp selector none|sim|sim-miswired|gpio|replay.
    std::string spectrometer;
    std::string tracker;
    std::string accel;
    std::string lampSelector;
    std::string replayFrom; // the recording that devices set to 'replay' play back
    std::string sitePath;   // --site: [sources] and [tracker] T_booth_tracker (calibrate)
    std::string output = "headless";
    std::uint64_t frames = 180;
    std::string size; // headless: 960x600 when not given; kms: the mode's size
    std::string panelSizeMm;
    double rateHz = 60.0;
    std::string record;
    bool force = false; // --force: overwrite an existing recording
    int recordFlushMs = 500;
    std::string digests;
    std::string snapshot;
    bool fast = false;
    std::string scene;
    std::string renderer = "booth";
    std::string basis; // empty: adaptive_k6 for the booth renderer, replica_k6 for the flat one
    std::string displayProfile;
    bool uncalibrated = false;
    std::string displayInverse = "analytic";
    std::string gamut = "hue";
    bool noViewing = false;
    bool noFlare = false;
    bool falseColour = false;
    bool planner = false;
    std::string planCache;
    bool recordDigests = true; // format 4: XXH3-64 of every displayed frame in the recording
    double thumbnailHz = 1.0;
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
};

constexpr int kExitConfig = 78; // EX_CONFIG: the unit's RestartPreventExitStatus

std::string dataPath(const std::string& p)
{
    const std::filesystem::path path(p);
    return path.is_relative() ? (dataDir() / path).string() : path.string();
}

// The site file's values for every option the command line did not give.
void applySite(const SiteConfig& s, RunOptions& o, const CLI::App& cmd)
{
    const auto unset = [&cmd](const char* name) { return cmd.get_option(name)->count() == 0; };
    if (unset("--hal")) {
        o.hal = s.hal;
    }
    if (unset("--replay-file")) {
        o.replayFile = s.replayFile;
    }
    if (unset("--rate")) {
        o.rateHz = s.rateHz;
    }
    if (unset("--output")) {
        o.output = s.output;
    }
    if (unset("--size") && o.output != "kms") { // on KMS the frame is the mode's size
        o.size = s.size;
    }
    if (unset("--kms-device")) {
        o.outputChoice.kms.device = s.kmsDevice;
    }
    if (unset("--kms-connector")) {
        o.outputChoice.kms.connector = s.kmsConnector;
    }
    if (unset("--scene") && !s.sceneDir.empty()) {
        o.scene = dataPath(s.sceneDir);
    }
    if (unset("--renderer")) {
        o.renderer = s.renderer;
    }
    if (unset("--display-profile") && unset("--uncalibrated") && !s.displayProfile.empty()) {
        o.displayProfile = dataPath(s.displayProfile);
    }
    if (unset("--tracker-port")) {
        o.live.trackerPort = s.trackerPort;
    }
    if (unset("--tracker-bind")) {
        o.live.trackerBind = s.trackerBind;
    }
    if (unset("--iio-root")) {
        o.live.iioRoot = s.iioRoot;
    }
    if (unset("--accel-name")) {
        o.live.accelName = s.accelName;
    }
    if (unset("--accel-axes")) {
        o.live.accelAxes = s.accelAxes;
    }
    if (unset("--lamp-gpio")) {
        o.live.lampGpio = s.lampGpio;
    }
    if (unset("--spectrometer-serial")) {
        o.live.spectrometerSerial = s.spectrometerSerial;
    }
    if (unset("--record-flush-ms")) {
        o.recordFlushMs = s.flushMs;
    }
}

// Whether the display profile is not a characterised panel: the nominal model, or a profile fitted
// from synthetic measurements (its description says so, as 'replica display fit --synthetic'
// writes it).
bool syntheticDisplay(const RunConfig& config)
{
    if (config.display == kUncalibratedDisplay) {
        return true;
    }
    std::ifstream in(dataPath(config.display));
    std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    try {
        const auto j = nlohmann::json::parse(text);
        return j.value("description", std::string()).find("SYNTHETIC") != std::string::npos;
    } catch (const std::exception&) {
        return false; // buildAppliance reports an unreadable profile
    }
}

std::optional<std::pair<int, int>> parseSize(const std::string& s)
{
    int w = 0;
    int h = 0;
    char x = 0;
    char extra = 0;
    if (std::sscanf(s.c_str(), "%d%c%d%c", &w, &x, &h, &extra) != 3 || (x != 'x' && x != 'X') ||
        !frameSizeOk(w, h)) {
        return std::nullopt;
    }
    return std::make_pair(w, h);
}

// The run's option that chooses a device kind's source: --spectrometer, --lamp-selector.
std::string deviceOption(const recordings::DeviceKindBase& kind)
{
    std::string s = kind.name();
    std::replace(s.begin(), s.end(), '_', '-');
    return s;
}

// Where each device kind's source comes from (kind name -> "live", "opentrack", "hid", "gpio",
// "sim", "sim-miswired", "replay" or "none").
struct DeviceChoice {
    std::map<std::string, std::string> from;
    const std::string& of(const recordings::DeviceKindBase& kind) const
    {
        static const std::string kNone = "none";
        const auto it = from.find(kind.name());
        return it != from.end() ? it->second : kNone;
    }
    static bool isSim(const std::string& v) { return v.rfind("sim", 0) == 0; }
    static bool isLive(const std::string& v) { return v != "none" && v != "replay" && !isSim(v); }
    template <typename Pred>
    bool any(Pred p) const
    {
        return std::any_of(from.begin(), from.end(), [&p](const auto& e) { return p(e.second); });
    }
    bool anyLive() const { return any(isLive); }
    bool anyReplay() const
    {
        return any([](const std::string& v) { return v == "replay"; });
    }
    bool anySim() const { return any(isSim); }
};

// Each device's source: --hal gives the default, --spectrometer/--tracker/--accel/--lamp-selector
// override it per device. Usage errors come back as InvalidArgument.
Expected<DeviceChoice> chooseDevices(const RunOptions& o)
{
    if (o.hal != "sim" && o.hal != "live" && o.hal != "replay") {
        return makeError(ErrorCode::InvalidArgument,
                         fmt::format("--hal {}: expected 'sim' (built-in simulated sensors), "
                                     "'live' (USB2000+, opentrack, IIO accelerometer) or 'replay' "
                                     "(the samples of --replay-file)",
                                     o.hal));
    }
    DeviceChoice c;
    auto& spectrometer = c.from[recordings::spectrometerKind().name()];
    auto& tracker = c.from[recordings::trackerKind().name()];
    auto& accel = c.from[recordings::accelKind().name()];
    auto& lampSelector = c.from[recordings::lampSelectorKind().name()];
    spectrometer = o.spectrometer.empty() ? o.hal : o.spectrometer;
    tracker = !o.tracker.empty() ? o.tracker : o.hal == "live" ? "opentrack" : o.hal;
    accel = o.accel.empty() ? o.hal : o.accel;
    lampSelector =
            !o.lampSelector.empty() ? o.lampSelector : (o.live.lampGpio.empty() ? "none" : "gpio");
    auto oneOf = [](const std::string& v, std::initializer_list<const char*> allowed) {
        for (const char* a : allowed) {
            if (v == a) {
                return true;
            }
        }
        return false;
    };
    if (!oneOf(spectrometer, {"live", "sim", "replay"}) ||
        !oneOf(tracker, {"opentrack", "hid", "sim", "replay"}) ||
        !oneOf(accel, {"live", "sim", "replay"}) ||
        !oneOf(lampSelector, {"none", "gpio", "sim", "sim-miswired", "replay"})) {
        return makeError(
                ErrorCode::InvalidArgument,
                fmt::format("sources spectrometer={} tracker={} accel={} lamp_selector={}: "
                            "expected spectrometer and accel live|sim|replay, tracker "
                            "opentrack|hid|sim|replay, lamp_selector "
                            "none|gpio|sim|sim-miswired|replay",
                            spectrometer, tracker, accel, lampSelector));
    }
    if (lampSelector == "gpio" && o.live.lampGpio.empty()) {
        return makeError(ErrorCode::InvalidArgument,
                         "--lamp-selector gpio needs --lamp-gpio CHIP:OFFSET,OFFSET,... (one line "
                         "per lamp)");
    }
    if (!o.live.lampGpio.empty() && lampSelector != "gpio") {
        return makeError(ErrorCode::InvalidArgument,
                         fmt::format("--lamp-gpio {} and --lamp-selector {} contradict each other: "
                                     "the GPIO switch is --lamp-selector gpio",
                                     o.live.lampGpio, lampSelector));
    }
    if (c.anyLive() && o.fast) {
        return makeError(ErrorCode::InvalidArgument,
                         "--fast needs simulated or replayed sensors: live sensors run on the "
                         "wall clock");
    }
    if (c.anyReplay() != !o.replayFrom.empty()) {
        return makeError(ErrorCode::InvalidArgument,
                         c.anyReplay() ? "a device set to 'replay' needs --replay-from "
                                         "RECORDING.mcap"
                                       : "--replay-from is for devices set to 'replay' (e.g. "
                                         "--tracker replay)");
    }
    return c;
}

Expected<Sources>
makeRunSources(const RunOptions& o, const Appliance& appliance, const hal::Clock& liveClock)
{
    auto choice = chooseDevices(o);
    if (!choice) {
        return tl::unexpected(choice.error());
    }
    const DeviceChoice& c = *choice;
    auto log = logger("replica");
    Sources sim;
    const std::string& lampFrom = c.of(recordings::lampSelectorKind());
    if (c.anySim()) {
        const bool simLamp = DeviceChoice::isSim(lampFrom);
        auto made = makeSimSources(appliance, simLamp ? lampFrom : std::string("none"));
        if (!made) {
            return tl::unexpected(made.error());
        }
        sim = std::move(*made);
    }
    Sources replayed;
    if (c.anyReplay()) {
        auto recording = recordings::readRecording(o.replayFrom);
        if (!recording) {
            return tl::unexpected(recording.error());
        }
        replayed = makeReplaySources(*recording);
        for (const auto* kind : recordings::deviceKinds()) {
            if (c.of(*kind) == "replay" && replayed.get(*kind) == nullptr) {
                return makeError(ErrorCode::InvalidArgument,
                                 fmt::format("--{} replay: {} has no {} channel",
                                             deviceOption(*kind), o.replayFrom,
                                             kind->names().displayName));
            }
        }
    }
    Sources live;
    if (c.anyLive()) {
        LiveOptions lo = o.live;
        const std::string& trackerFrom = c.of(recordings::trackerKind());
        lo.spectrometer = c.of(recordings::spectrometerKind()) == "live";
        lo.tracker = DeviceChoice::isLive(trackerFrom) ? trackerFrom : std::string();
        lo.accel = c.of(recordings::accelKind()) == "live";
        if (lampFrom != "gpio") {
            lo.lampGpio.clear();
        }
        auto made = makeLiveSources(liveClock, lo, appliance.booth.lights.size());
        if (!made) {
            return tl::unexpected(made.error());
        }
        live = std::move(*made);
    }
    // Each device kind from where the choice says; "none": the run has no such device.
    Sources out;
    for (const auto* kind : recordings::deviceKinds()) {
        const std::string& from = c.of(*kind);
        Sources* src = from == "none"              ? nullptr
                       : DeviceChoice::isSim(from) ? &sim
                       : from == "replay"          ? &replayed
                                                   : &live;
        if (src != nullptr) {
            out.set(*kind, src->take(*kind));
        }
    }
    // Say which devices do not come from the booth, so nobody mistakes a simulated one for it.
    if (c.anyLive()) {
        for (const auto* device : recordings::deviceKinds()) {
            const std::string& name = device->name();
            const std::string& kind = c.of(*device);
            if (device->names().optional) {
                continue; // said only for the sensors every run has
            }
            if (kind == "sim" || kind == "replay") {
                log->warn("{} is {}: {}; the display follows it, not the booth's {}", name,
                          kind == "sim" ? "simulated" : "replayed",
                          kind == "sim" ? "the scripted scenario" : o.replayFrom, name);
            }
        }
    }
    return out;
}

int runMain(const RunOptions& given)
{
    auto log = logger("replica");
    RunOptions o = given;
    if (!o.sitePath.empty()) {
        // The site file's [sources] fill in what the command line leaves open.
        auto site = readSiteSources(o.sitePath);
        if (!site) {
            log->error("{}", site.error().message);
            return kExitUsage;
        }
        for (auto [cli, fromSite] :
             {std::pair{&o.spectrometer, &site->spectrometer},
              std::pair{&o.tracker, &site->tracker}, std::pair{&o.accel, &site->accel},
              std::pair{&o.lampSelector, &site->lampSelector}}) {
            if (cli->empty()) {
                *cli = *fromSite;
            }
        }
    }
    if (o.hal == "replay" && o.replayFile.empty()) {
        log->error("--hal replay needs --replay-file RECORDING (or run.replay_file in the site "
                   "file)");
        return kExitUsage;
    }
    if (o.hal == "replay" && o.replayFrom.empty()) {
        o.replayFrom = o.replayFile; // every device replays it unless told otherwise
    }
    if (o.hal == "live" && o.fast) {
        log->error("--fast needs the simulated sensors: live sensors run on the wall clock");
        return kExitUsage;
    }
    if (auto choice = chooseDevices(o); !choice) { // usage errors before anything is built
        log->error("{}", choice.error().message);
        return kExitUsage;
    }
    if (o.output != "headless" && o.output != "kms") {
        log->error("--output {}: expected 'headless' (no display) or 'kms' (fullscreen on the "
                   "console, no display server)",
                   o.output);
        return kExitUsage;
    }
    if (!o.record.empty() && !o.force) {
        // Refused before the run starts (the writer refuses it again, race-free): an existing
        // recording is evidence, and a link must not redirect the write.
        struct stat st {
        };
        if (::lstat(o.record.c_str(), &st) == 0 &&
            (S_ISLNK(st.st_mode) || (S_ISREG(st.st_mode) && st.st_size > 0))) {
            log->error("--record {}: {}", o.record,
                       S_ISLNK(st.st_mode) ? "is a symbolic link; name the file itself"
                                           : "already exists; pass --force to overwrite it, or "
                                             "name a new file");
            return kExitUsage;
        }
    }
    if (o.output == "kms" && !o.size.empty()) {
        log->error("--size {}: on KMS the frame is the display mode's size; choose the mode with "
                   "--kms-mode WIDTHxHEIGHT",
                   o.size);
        return kExitUsage;
    }
    const auto size = parseSize(o.size.empty() ? std::string("960x600") : o.size);
    if (!size) {
        log->error("--size {}: expected WIDTHxHEIGHT, e.g. 960x600, each side 1-{} and at most "
                   "{}:1",
                   o.size, kMaxFrameSide, kMaxFrameAspect);
        return kExitUsage;
    }
    RunConfig config;
    config.width = size->first;
    config.height = size->second;
    if (!o.panelSizeMm.empty()) {
        auto panel = parseSizeMm(o.panelSizeMm);
        if (!panel) {
            log->error("--panel-size-mm: {}", panel.error().message);
            return kExitUsage;
        }
        config.stand.panelWidthM = panel->width / 1000.0;
        config.stand.panelHeightM = panel->height / 1000.0;
    }
    config.rateHz = o.rateHz;
    config.renderer = o.renderer;
    // The flat renderer has no 36-band scene to re-encode: it keeps the best fixed basis.
    config.basis = !o.basis.empty() ? o.basis
                                    : (o.renderer == "flat" ? std::string("replica_k6")
                                                            : std::string(kAdaptiveBasis));
    if (!o.scene.empty()) {
        // Stored relative to the data folder when it is inside it, so that a recording replays on
        // another installation.
        std::error_code ec;
        const auto abs = std::filesystem::weakly_canonical(o.scene, ec);
        const auto data = std::filesystem::weakly_canonical(dataDir(), ec);
        const auto rel = abs.lexically_relative(data);
        config.sceneDir = !rel.empty() && *rel.begin() != ".." ? rel.string() : abs.string();
        if (!std::filesystem::is_regular_file(abs / "scene.json", ec)) {
            log->error("--scene {}: no scene.json there; name a scene folder such as {}", o.scene,
                       (dataDir() / "scenes" / "painting").string());
            return kExitUsage;
        }
    }
    if (o.uncalibrated && !o.displayProfile.empty()) {
        log->error("--uncalibrated and --display-profile {} contradict each other: give one",
                   o.displayProfile);
        return kExitUsage;
    }
    if (o.uncalibrated) {
        config.display = kUncalibratedDisplay;
        log->warn("--uncalibrated: driving a nominal sRGB-like {} cd/m^2 model, not a "
                  "characterised panel; colours on screen are not the surface's",
                  config.displayPeakCdM2);
    } else if (!o.displayProfile.empty()) {
        // Like the scene: relative to the data folder when inside it, so that replay (which
        // opens only files inside the data folders) finds it on another installation.
        std::error_code ec;
        const auto abs = std::filesystem::weakly_canonical(
                std::filesystem::absolute(o.displayProfile, ec), ec);
        const auto data = std::filesystem::weakly_canonical(dataDir(), ec);
        const auto rel = abs.lexically_relative(data);
        config.display = !rel.empty() && *rel.begin() != ".."
                                 ? rel.string()
                                 : std::filesystem::absolute(o.displayProfile, ec).string();
    }
    config.displayInverse = o.displayInverse;
    config.gamutMapping = o.gamut;
    config.viewingCompensation = !o.noViewing;
    config.flareSubtraction = !o.noFlare;
    config.falseColour = o.falseColour;
    config.planner = o.planner;
    config.plannerCache = o.planCache;
    if (o.site) {
        const SiteConfig& site = *o.site;
        config.booth = site.boothId;
        config.boothDimmer = site.boothDimmer;
        config.boothDimmerAuto = site.boothDimmerAuto;
        config.planner = config.planner || site.renderPlanner;
        const double panelW = config.stand.panelWidthM, panelH = config.stand.panelHeightM;
        config.stand = site.stand;
        if (!o.panelSizeMm.empty()) { // the command line wins over the site file
            config.stand.panelWidthM = panelW;
            config.stand.panelHeightM = panelH;
        }
        config.trackerInBooth = site.trackerInBooth();
        config.defaultLamp = site.defaultLamp;
        config.defaultEyeM = site.defaultEyeM;
        config.defaultTiltRad = site.defaultTiltDeg * std::numbers::pi / 180.0;
    }
    if (!o.sitePath.empty()) {
        auto t = readTrackerTransform(o.sitePath);
        if (!t && t.error().code != ErrorCode::NotFound) {
            log->error("{}", t.error().message);
            return kExitFailure;
        }
        if (t) {
            config.trackerInBooth = *t; // the calibration wins over the site's angles
            log->info("tracker pose in the booth from {} (T_booth_tracker)", o.sitePath);
        } else {
            log->warn("{}; using [tracker] rotation_deg and translation_m (absent: the fixed "
                      "mounting)",
                      t.error().message);
        }
    }
    if (o.hal == "live" && syntheticDisplay(config)) {
        const bool allowed = o.site && o.site->allowSynthetic;
        for (int i = 0; i < 3; ++i) {
            log->warn("!!! LIVE RUN ON A SYNTHETIC DISPLAY PROFILE ({}): the colours on this "
                      "screen are not the surface's. Characterise the panel ('replica display "
                      "fit') and set display.profile in the site file. !!!",
                      config.display);
        }
        if (o.kiosk && !allowed) {
            log->error("{}: the kiosk refuses a live run on a synthetic display profile; set "
                       "display.profile to the panel's profile, or display.allow_synthetic = "
                       "true to accept wrong colours",
                       o.site ? o.site->source.string() : std::string("(no site file)"));
            return kExitConfig;
        }
    }

    OutputChoice outputChoice = o.outputChoice;
    outputChoice.kind = o.output;
    outputChoice.frameFromMode = true;
    // The EDID's physical size only when neither the command line nor a site file gives one.
    outputChoice.panelFromDisplay = o.panelSizeMm.empty() && !o.site;
    auto appliance = buildAppliance(config, outputChoice);
    if (!appliance) {
        log->error("{}", appliance.error().message);
        return kExitFailure;
    }
    // Live devices stamp samples on this clock; the loop's ticks start with it (within the few
    // milliseconds between here and the first tick, which only delays samples by that much).
    hal::SteadyClock liveClock;
    auto sources = makeRunSources(o, **appliance, liveClock);
    if (!sources) {
        log->error("{}", sources.error().message);
        return kExitFailure; // usage errors were caught before anything was built
    }
    if (!o.faults.empty()) {
        auto plan = parseFaultPlan(o.faults);
        if (!plan) {
            log->error("{}", plan.error().message);
            return kExitUsage;
        }
        injectFaults(*sources, *plan);
        log->warn("injecting faults into the sensor samples: {}", o.faults);
    }
    log->info("{}; data {}", versionString(), dataDir().string());
    std::string devices;
    for (const auto& e : sources->entries()) {
        if (e.source) {
            const auto& info = e.source->info();
            devices += fmt::format("{}{}={} [{} {}]", devices.empty() ? "" : ", ", e.kind->name(),
                                   hal::toString(info.kind), info.model, info.serial);
        }
    }
    log->info("hal: {}; output={}; renderer={} on {}; {}x{} at {} Hz; display {}", devices,
              (*appliance)->output->name(), (*appliance)->renderer->description(),
              (*appliance)->output->glRenderer(), (*appliance)->config.width,
              (*appliance)->config.height, config.rateHz, (*appliance)->displayProfileId);

    std::unique_ptr<recordings::RecordingWriter> recorder;
    std::unique_ptr<SessionRecorder> sessions;
    bool recordFailed = false;
    const bool kioskRecording = o.kiosk && o.site && o.site->recordingEnabled && o.record.empty();
    if (!o.record.empty() || kioskRecording) {
        recordings::SessionInfo session;
        session.softwareVersion = versionString();
        // The configuration as built: the scene folder and digest, the display profile's digest.
        const RunConfig& built = (*appliance)->config;
        // The resolved configuration: the run configuration as built, the options the run
        // resolved from the command line and the site file, and the site file itself.
        auto resolved = nlohmann::json::parse(built.toJson());
        resolved["run_options"] = {{"hal", o.hal},
                                   {"replay_file", o.replayFile},
                                   {"output", o.output},
                                   {"kms_device", outputChoice.kms.device},
                                   {"kms_connector", outputChoice.kms.connector},
                                   {"kiosk", o.kiosk},
                                   {"tracker_port", o.live.trackerPort},
                                   {"tracker_bind", o.live.trackerBind},
                                   {"iio_root", o.live.iioRoot.string()},
                                   {"accel_name", o.live.accelName},
                                   {"accel_axes", o.live.accelAxes},
                                   {"lamp_gpio", o.live.lampGpio},
                                   {"spectrometer_serial", o.live.spectrometerSerial}};
        if (o.site) {
            resolved["site"] = nlohmann::json::parse(o.site->toJson());
        }
        session.configJson = resolved.dump();
        session.boothModel = built.booth;
        session.scene = built.scene;
        session.displayProfile = (*appliance)->displayProfileId;
        session.wallClockStartNs = std::chrono::duration_cast<std::chrono::nanoseconds>(
                                           std::chrono::system_clock::now().time_since_epoch())
                                           .count();
        for (const auto& e : sources->entries()) {
            if (e.source) {
                session.devices[e.kind->name()] = e.source->info();
            }
        }
        recordings::WriterOptions options;
        options.flushInterval = std::chrono::milliseconds(o.recordFlushMs);
        options.overwrite = o.force;
        // Called once from the writer thread; the loop keeps displaying without the recording.
        options.onError = [log](const Error& e) {
            log->error("{}; recording stopped, display continues", e.message);
        };
        if (kioskRecording) {
            const SiteConfig& site = *o.site;
            const std::filesystem::path dir = site.recordingDirectory;
            std::error_code ec;
            std::filesystem::create_directories(dir, ec);
            recoverUnfinished(dir);
            RotationPolicy policy;
            policy.rotateBytes = site.rotateBytes;
            policy.rotateAge = std::chrono::seconds(site.rotateSeconds);
            policy.keepBytes = site.keepBytes;
            // Each rotated file starts with the estimators' state ("state_at_start": the
            // classifier's hysteresis, the lamp selector's arbitration, the encoding, the held
            // eye and tilts), so that it replays alone, bit for bit, as the panel showed it.
            const state::SceneEstimator* estimator = (*appliance)->updater.get();
            sessions = std::make_unique<SessionRecorder>(
                    dir, policy, [session, options, estimator](const std::filesystem::path& path) {
                        if (!estimator->started()) {
                            return recordings::RecordingWriter::create(path, session, options);
                        }
                        recordings::SessionInfo withState = session;
                        auto resolvedJson = nlohmann::json::parse(session.configJson);
                        resolvedJson[kStateAtStartKey] = estimator->save();
                        withState.configJson = resolvedJson.dump();
                        return recordings::RecordingWriter::create(path, withState, options);
                    });
            if (auto ok = sessions->open(); !ok) {
                log->error("{}; running without recording", ok.error().message);
                sessions.reset();
            }
        } else {
            auto w = recordings::RecordingWriter::create(o.record, session, options);
            if (!w) {
                // The appliance still displays; the run reports failure at the end.
                log->error("{}; running without recording", w.error().message);
                recordFailed = true;
            } else {
                recorder = std::move(*w);
            }
        }
    }

    // What the panel showed, into the recording (format 4 channels).
    std::unique_ptr<ShownRecorder> shown;
    if (recorder) {
        ShownOptions so;
        so.displayDigests = o.recordDigests;
        so.thumbnailHz = o.thumbnailHz;
        so.thumbnailWidth = o.thumbnailWidth;
        shown = std::make_unique<ShownRecorder>(*recorder, **appliance, so);
    }
    FrameOutputs outputs(!o.digests.empty(), !o.snapshot.empty());
    // --frames 0: run until SIGINT/SIGTERM (the kiosk), closing the recording properly.
    installStopSignals();
    const TickSource ticks = o.frames == 0 ? endlessTicks(config.periodNs())
                                           : fixedRateTicks(config.periodNs(), o.frames);
    // Scan-out needs the display pixels of every frame, digests or not.
    auto readback = outputs.readback();
    if ((*appliance)->output->needsPixels() && readback == pipeline::render::Readback::None) {
        readback = pipeline::render::Readback::Display;
    }
    if (shown) {
        readback = std::max(readback, shown->readback());
    }
    auto keep = outputs.callback();
    const FrameCallback onFrame = [&](const recordings::FrameRecord& f,
                                      const pipeline::scene::SceneState& state,
                                      const pipeline::render::RenderedFrame& image) {
        keep(f, state, image);
        if (shown) {
            shown->onFrame(f, state, image);
        }
    };
    SystemdNotifier notifier;
    LoopOptions loopOptions;
    loopOptions.skipLateTicks = true;
    loopOptions.periodNs = config.periodNs();
    loopOptions.afterFrame = [&notifier](const LoopStats& s) {
        notifier.frameShown(s.frames, s.skippedTicks);
    };
    if (sessions) {
        loopOptions.nextRecorder = [&sessions](recordings::RecordingWriter*) {
            return sessions->afterFrame();
        };
    }
    const auto wallStart = std::chrono::steady_clock::now();
    auto stats = runFrames(**appliance, *sources, ticks, o.fast ? Pacing::Fast : Pacing::Realtime,
                           sessions ? sessions->current() : recorder.get(), readback, onFrame,
                           loopOptions);
    const double wallS =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - wallStart).count();
    notifier.stopping();
    if (shown) {
        shown->finish(); // the last thumbnail and the log tap, before the writer closes
    }
    if (!stats) {
        log->error("{}", stats.error().message);
        return kExitFailure;
    }
    int code = recordFailed ? kExitFailure : kExitOk;
    if (sessions) {
        if (auto closed = sessions->close(); !closed) {
            log->warn("session {} is incomplete; the next start recovers it",
                      sessions->currentPath().string());
            code = kExitFailure;
        } else {
            fmt::print("recording: {} ({} rotations)\n", sessions->currentPath().string(),
                       sessions->rotations());
        }
    }
    nlohmann::json summary{{"command", "run"}, {"frames", stats->frames}, {"wall_s", wallS}};
    if (recorder) {
        if (auto closed = recorder->close(); !closed) {
            // Already logged by onError when it happened; say where the run stands.
            log->warn("recording {} is incomplete; 'replica recover' rebuilds what was written",
                      o.record);
            code = kExitFailure;
        } else if (!o.json) {
            fmt::print("recording: {}\n", o.record);
        }
        const auto ws = recorder->stats();
        summary["recording"] = {{"file", o.record},      {"complete", code == kExitOk},
                                {"bytes", ws.bytes},     {"messages", ws.messages},
                                {"dropped", ws.dropped}, {"rejected_nonfinite", ws.rejected},
                                {"chunks", ws.chunks}};
    }
    if (shown) {
        const auto ss = shown->stats();
        const auto n = static_cast<double>(std::max<std::uint64_t>(ss.thumbnails, 1));
        const auto d = static_cast<double>(std::max<std::uint64_t>(ss.digests, 1));
        summary["shown"] = {{"display_digests", ss.digests},
                            {"digest_ms_mean", ss.digestMsTotal / d},
                            {"thumbnails", ss.thumbnails},
                            {"thumbnail_bytes", ss.thumbnailBytes},
                            {"thumbnails_skipped", ss.thumbnailsSkipped},
                            {"thumbnail_copy_ms_mean", ss.copyMsTotal / n},
                            {"thumbnail_encode_ms_mean", ss.encodeMsTotal / n},
                            {"light_changes", ss.lightChanges},
                            {"poses", ss.poses}};
        log->info("recorded what was shown: {} display digests ({:.3f} ms each in the frame), {} "
                  "thumbnails ({} bytes; {:.3f} ms copy in the frame, {:.2f} ms encode off it), {} "
                  "light decisions, {} poses",
                  ss.digests, ss.digestMsTotal / d, ss.thumbnails, ss.thumbnailBytes,
                  ss.copyMsTotal / n, ss.encodeMsTotal / n, ss.lightChanges, ss.poses);
    }
    if (auto ok = outputs.finish(o.digests, o.snapshot); !ok) {
        log->error("{}", ok.error().message);
        return kExitFailure;
    }
    if (!o.digests.empty()) {
        summary["digests"] = {{"file", o.digests}, {"hash", digestHashName(kDigestHash)}};
        if (!o.json) {
            fmt::print("digests: {}\n", o.digests);
        }
    }
    if (!o.snapshot.empty()) {
        summary["snapshot"] = o.snapshot;
        if (!o.json) {
            fmt::print("snapshot: {}\n", o.snapshot);
        }
    }
    if (const auto* selector = sources->get(recordings::lampSelectorKind())) {
        log->info("lamp selector {} [{} {}]: overruled by the spectrometer {} times",
                  hal::toString(selector->info().kind), selector->info().model,
                  selector->info().serial, (*appliance)->updater->lampArbiter().overruled());
    }
    std::string dropped;
    for (const auto& e : sources->entries()) {
        if (e.source) {
            dropped += fmt::format("{}{} {}", dropped.empty() ? "" : ", ",
                                   e.kind->names().displayName, stats->dropped[e.kind->name()]);
        }
    }
    log->info("{} frames; dropped samples: {}; late frames {}, skipped ticks {}; out of gamut: "
              "mean {:.4f}, max {:.4f} of the surface's pixels (above the panel's peak: mean "
              "{:.4f}, max {:.4f})",
              stats->frames, dropped, stats->lateFrames, stats->skippedTicks,
              stats->meanOutOfGamutFraction(), stats->maxOutOfGamutFraction,
              stats->meanOverPeakFraction(), stats->maxOverPeakFraction);
    const FrameTimes& t = stats->frameTimes;
    const double periodMs = 1000.0 / o.rateHz;
    // --digests reads every frame back as float XYZ and hashes it (XXH3-64, digest format 2; about
    // 1 ms for the 11.5 MB of a 960x600 frame, docs/performance.md) inside each frame's time; the
    // read-back of the XYZ frame costs more than the hash. Said so that the figure is not taken
    // for the appliance's.
    log->info("frame time: mean {:.1f} ms ({:.0f} frames/s), 50th percentile {:.1f}, 95th {:.1f}, "
              "99th {:.1f}, max {:.1f}; {} of {} frames took the whole {:.1f} ms period or more{}",
              t.meanMs(), t.meanMs() > 0.0 ? 1000.0 / t.meanMs() : 0.0, t.percentileMs(0.50),
              t.percentileMs(0.95), t.percentileMs(0.99), t.maxMs(), t.atLeast(periodMs), t.count(),
              periodMs,
              o.digests.empty() ? ""
                                : " (including --digests: each frame read back as XYZ and "
                                  "hashed, which a run without it does not do)");
    summary["exit_code"] = code;
    summary["late_frames"] = stats->lateFrames;
    summary["dropped"] = nlohmann::json::object();
    for (const auto* kind : recordings::deviceKinds()) {
        const auto it = stats->dropped.find(kind->name());
        summary["dropped"][kind->name()] = it != stats->dropped.end() ? it->second : 0;
    }
    summary["frame_time_ms"] = {{"mean", t.meanMs()},
                                {"p50", t.percentileMs(0.50)},
                                {"p95", t.percentileMs(0.95)},
                                {"p99", t.percentileMs(0.99)},
                                {"max", t.maxMs()},
                                {"at_least_period", t.atLeast(periodMs)}};
    // Fractions of the surface's pixels (the black surround is below black by construction).
    summary["out_of_gamut"] = {{"mean", stats->meanOutOfGamutFraction()},
                               {"max", stats->maxOutOfGamutFraction},
                               {"over_peak_mean", stats->meanOverPeakFraction()},
                               {"over_peak_max", stats->maxOverPeakFraction},
                               {"of", "surface pixels"}};
    if (o.json) {
        fmt::print("{}\n", summary.dump(2));
    }
    return code;
}

} // namespace

void addKmsOptions(CLI::App& cmd, KmsOptions& kms)
{
    cmd.add_option("--kms-device", kms.device, "kms: the DRM card to drive")->capture_default_str();
    cmd.add_option("--kms-connector", kms.connector,
                   "kms: connector name, e.g. HDMI-A-1 (default: the first connected)");
    cmd.add_option("--kms-mode", kms.mode,
                   "kms: the mode, WIDTHxHEIGHT or WIDTHxHEIGHT@HZ (default: the display's "
                   "preferred mode)");
    cmd.add_option("--kms-modeset", kms.modeset,
                   "kms: auto (atomic where the driver has it, else legacy), atomic or legacy")
            ->check(CLI::IsMember({"auto", "atomic", "legacy"}))
            ->capture_default_str();
    cmd.add_option("--kms-path", kms.path,
                   "kms: auto (EGL on a GBM surface, else CPU copies into dumb buffers), gbm or "
                   "dumb")
            ->check(CLI::IsMember({"auto", "gbm", "dumb"}))
            ->capture_default_str();
}

void registerRunCommand(CLI::App& app, int& exitCode)
{
    auto opts = std::make_shared<RunOptions>();
    auto* cmd =
            app.add_subcommand("run", "run the appliance: sensors -> scene -> render -> output at "
                                      "a fixed rate");
    cmd->add_option("--config", opts->config,
                    "site file (TOML, docs/appliance.md); the command line overrides it. "
                    "--kiosk reads " +
                            defaultSiteConfigPath().string() + " when none is given");
    cmd->add_flag("--kiosk", opts->kiosk,
                  "the gallery appliance: run until stopped, record sessions into the site "
                  "file's recording.directory (rotated, oldest deleted beyond keep_bytes, a "
                  "crashed session recovered at start); refuses a live run on a synthetic "
                  "display profile unless display.allow_synthetic");
    cmd->add_option("--hal", opts->hal,
                    "sensor sources: sim (built-in simulated sensors), live (USB2000+ over "
                    "libusb, opentrack UDP head poses, IIO accelerometer) or replay (the samples "
                    "of --replay-file, then the last state held)")
            ->capture_default_str();
    cmd->add_option("--replay-file", opts->replayFile, "--hal replay: the recording to play");
    cmd->add_option("--inject-faults", opts->faults,
                    "soak tests: nan-pose=N (every Nth head pose NaN), saturate=N (every Nth "
                    "spectrum saturated), unplug=EVERY_S/FOR_S (spectrometer and tracker "
                    "silent FOR_S of every EVERY_S)")
            ->group("Testing");
    cmd->add_option("--tracker-port", opts->live.trackerPort,
                    "live: UDP port opentrack sends head poses to")
            ->capture_default_str();
    cmd->add_option("--tracker-bind", opts->live.trackerBind, "live: address to listen on")
            ->capture_default_str();
    cmd->add_option("--iio-root", opts->live.iioRoot, "live: where IIO devices are listed")
            ->capture_default_str();
    cmd->add_option("--accel-name", opts->live.accelName,
                    "live: the accelerometer's IIO name (default: the first one)");
    cmd->add_option("--accel-axes", opts->live.accelAxes,
                    "live: sensor axis for each panel axis (x right, y up, z out of the screen), "
                    "e.g. -y,x,z")
            ->capture_default_str();
    cmd->add_option("--lamp-gpio", opts->live.lampGpio,
                    "live: the booth's lamp selector switch, CHIP:OFFSET,OFFSET,... with one GPIO "
                    "line per lamp in the booth's lamp order (active low, pull-up), e.g. "
                    "gpiochip0:17,27,22; without it the spectrometer alone decides the light");
    cmd->add_option("--spectrometer-serial", opts->live.spectrometerSerial,
                    "live: open the USB2000+ whose USB serial number is this (as `lsusb -v` "
                    "shows it); default: the first one found");
    cmd->add_option("--lamp-selector", opts->lampSelector,
                    "the booth's lamp switch: none, gpio (the live switch on --lamp-gpio; the "
                    "default when that is given), sim (follows the simulated lamps, with contact "
                    "bounce), sim-miswired (its lines for lamps 1 and 2 swapped) or replay")
            ->check(CLI::IsMember({"none", "gpio", "sim", "sim-miswired", "replay"}));
    cmd->add_option("--spectrometer", opts->spectrometer,
                    "the spectrometer's source: live (USB2000+), sim or replay (default: --hal)")
            ->check(CLI::IsMember({"live", "sim", "replay"}));
    cmd->add_option("--tracker", opts->tracker,
                    "the head tracker's source: opentrack (UDP), hid (a USB HID eye/head tracker, "
                    "usage page 0x12), sim or replay (default: opentrack with --hal live, else "
                    "sim)")
            ->check(CLI::IsMember({"opentrack", "hid", "sim", "replay"}));
    cmd->add_option("--accel", opts->accel,
                    "the accelerometer's source: live (IIO), sim or replay (default: --hal)")
            ->check(CLI::IsMember({"live", "sim", "replay"}));
    cmd->add_option("--replay-from", opts->replayFrom,
                    "the recording that devices set to 'replay' play back (from its session "
                    "start)");
    cmd->add_option("--site", opts->sitePath,
                    "site configuration file (e.g. /etc/replica/replica.toml): [sources] "
                    "spectrometer/tracker/accel/lamp_selector (the command line wins) and the "
                    "calibrated tracker pose [tracker] T_booth_tracker from 'replica calibrate "
                    "tracker'");
    cmd->add_option(
            "--hid-tracker", opts->live.hidTracker,
            "--tracker hid: the hidraw node, e.g. /dev/hidraw3 (default: the first eye/head "
            "tracker found; 'replica probe' lists them)");
    cmd->add_option("--tracker-axes", opts->live.trackerAxes,
                    "--tracker hid: the device axis for x right, y up, z towards the viewer, e.g. "
                    "x,-y,z for a tracker whose y points down the screen")
            ->capture_default_str();
    cmd->add_option("--output", opts->output,
                    "frame output: headless (surfaceless EGL) or kms (fullscreen scan-out)")
            ->capture_default_str();
    addKmsOptions(*cmd, opts->outputChoice.kms);
    cmd->add_option("--frames", opts->frames,
                    "number of frames to run; 0 = until SIGINT/SIGTERM (the kiosk)")
            ->check(CLI::Range(std::uint64_t{0}, kMaxFrames))
            ->capture_default_str();
    cmd->add_option("--size", opts->size,
                    "headless: frame size WIDTHxHEIGHT (default 960x600); on kms the frame is the "
                    "mode's size");
    cmd->add_option("--panel-size-mm", opts->panelSizeMm,
                    "the panel's active area WIDTHxHEIGHT in millimetres, which the frame covers "
                    "(default: the display's EDID on kms, else 518x324, a 24-inch 16:10 panel)");
    cmd->add_option("--rate", opts->rateHz, "frame rate (Hz)")
            ->check(CLI::Range(1.0, 1000.0))
            ->capture_default_str();
    cmd->add_option("--record", opts->record, "write every sensor sample and frame input to FILE");
    cmd->add_flag("--force", opts->force,
                  "--record: overwrite FILE if it exists (never through a symbolic link)");
    cmd->add_option("--record-flush-ms", opts->recordFlushMs,
                    "close and sync the recording's open chunk at least this often (ms): a power "
                    "cut loses at most about this much")
            ->check(CLI::Range(10, 10000))
            ->capture_default_str();
    cmd->add_option("--record-digests", opts->recordDigests,
                    "with --record: an XXH3-64 digest of every frame sent to the panel in the "
                    "recording (/replica/display_digest; replay checks it)")
            ->capture_default_str();
    cmd->add_option("--thumbnail-hz", opts->thumbnailHz,
                    "with --record: PNG thumbnails of the displayed frame per second of session "
                    "time (/replica/thumbnail); 0: none")
            ->check(CLI::Range(0.0, 60.0))
            ->capture_default_str();
    cmd->add_option("--thumbnail-width", opts->thumbnailWidth, "thumbnail width (pixels)")
            ->check(CLI::Range(16, 4096))
            ->capture_default_str();
    cmd->add_flag("--json", opts->json,
                  "print a JSON summary (frames, frame times, drops, recording, outputs) on "
                  "standard output instead of the text lines");
    cmd->add_option("--digests", opts->digests, "write one digest per frame to FILE (JSON)");
    cmd->add_option("--snapshot", opts->snapshot, "write the last frame to FILE (PNG)");
    cmd->add_option("--scene", opts->scene,
                    "surface scene folder (scene.json + EXRs); default: the shipped ColorChecker, "
                    "data/scenes/colorchecker");
    cmd->add_option("--renderer", opts->renderer,
                    "booth (the scene lit by the booth model) or flat (the first recordings' patch "
                    "renderer)")
            ->check(CLI::IsMember({"booth", "flat"}))
            ->capture_default_str();
    cmd->add_option("--basis", opts->basis,
                    "channel basis: adaptive_k6 (re-encoded for each light, exact for the light "
                    "present; the default, booth renderer only), replica_k6 (fixed; the flat "
                    "renderer's default), general_k6, pca6, box6 (docs/accuracy.md)")
            ->check(CLI::IsMember(pipeline::spectral::channelBasisNames()));
    cmd->add_flag("--fast", opts->fast,
                  "do not wait for each tick's wall-clock time (same frames, rendered as fast as "
                  "possible)");
    cmd->add_option("--display-profile", opts->displayProfile,
                    "display profile (JSON, from 'replica display fit'); default: the shipped "
                    "data/displays/wide-ips-synthetic.json");
    cmd->add_flag("--uncalibrated", opts->uncalibrated,
                  "run without a display profile, on a nominal sRGB-like model (colours are then "
                  "not faithful)");
    cmd->add_option("--display-inverse", opts->displayInverse,
                    "inverse display model in the shader: analytic or lut3d")
            ->check(CLI::IsMember({"analytic", "lut3d"}))
            ->capture_default_str();
    cmd->add_option("--gamut", opts->gamut,
                    "out-of-gamut colours: hue (hue-keeping mapping) or clip (per channel; for "
                    "comparison)")
            ->check(CLI::IsMember({"hue", "clip"}))
            ->capture_default_str();
    cmd->add_flag("--no-viewing-compensation", opts->noViewing,
                  "drive every pixel as if seen on the panel normal");
    cmd->add_flag("--no-flare-subtraction", opts->noFlare,
                  "do not subtract the screen's own reflection of the booth light");
    cmd->add_flag("--planner", opts->planner,
                  "draw each lamp with the planner's lights, specular samples and horizon "
                  "directions (cached per scene, computed once when missing; recorded); the site "
                  "file's [render] planner = true asks the same");
    cmd->add_option("--plan-cache", opts->planCache,
                    "folder of the planner's cached plans (default $REPLICA_PLAN_CACHE, else "
                    "$XDG_CACHE_HOME/replica/plans, else ~/.cache/replica/plans)");
    cmd->add_flag("--false-colour", opts->falseColour,
                  "field-staff overlay: stripe out-of-gamut pixels (magenta: chroma, cyan: above "
                  "peak, blue: below black)");
    cmd->callback([opts, cmd, &exitCode] {
        RunOptions o = *opts;
        std::string file = o.config;
        if (file.empty() && o.kiosk) {
            file = defaultSiteConfigPath().string();
            std::error_code ec;
            if (!std::filesystem::exists(file, ec)) {
                logger("replica")->error("--kiosk: no site file at {}; install the package (it "
                                         "ships one) or pass --config FILE",
                                         file);
                exitCode = kExitConfig;
                return;
            }
        }
        if (!file.empty()) {
            auto site = loadSiteConfig(file);
            if (!site) {
                logger("replica")->error("{}", site.error().message);
                exitCode = kExitConfig;
                return;
            }
            if (!site->problems.empty()) {
                for (const auto& p : site->problems) {
                    logger("replica")->error("{}", formatProblem(file, p));
                }
                logger("replica")->error("{}: {} problems; 'replica config check {}' lists them",
                                         file, site->problems.size(), file);
                exitCode = kExitConfig;
                return;
            }
            o.site = site->config;
            applySite(*o.site, o, *cmd);
            // The site's log levels, unless the command line or $REPLICA_LOG set them.
            const auto* parent = cmd->get_parent();
            if (parent != nullptr && parent->get_option("--log-level")->count() == 0 &&
                std::getenv("REPLICA_LOG") == nullptr) {
                setupLogging(o.site->logLevel, true);
            }
        }
        if (o.kiosk && cmd->get_option("--frames")->count() == 0) {
            o.frames = 0;
        }
        exitCode = runMain(o);
    });
}

} // namespace replica::platform
