// The one resolution of a run's options and site file (run_resolve.h).
#include <cstdio>
#include <filesystem>
#include <iterator>
#include <numbers>

#include <arpa/inet.h>
#include <fmt/format.h>
#include <nlohmann/json.hpp>
#include <sys/stat.h>

#include <hal/accel/iio_accel.h>
#include <hal/lamp/gpio_lines.h>
#include <pipeline/base/data_dir.h>
#include <pipeline/base/input_file.h>
#include <pipeline/base/json_limits.h>
#include <pipeline/display/display_profile.h>
#include <pipeline/scene/booth.h>
#include <pipeline/surface/surface_scene.h>
#include <platform/cli/commands.h>
#include <platform/cli/run_resolve.h>
#include <platform/cli/run_sources.h>
#include <platform/logging.h>
#include <platform/output/display_geometry.h>
#include <platform/site_file.h>
#include <recordings/recording.h>

namespace replica::platform::run_cli {
namespace {

Refusal makeRefusal(int code, std::vector<std::string> lines, SiteProblem problem = {})
{
    Refusal r;
    r.code = code;
    r.lines = std::move(lines);
    r.problem = std::move(problem);
    return r;
}

Refusal usage(std::string line)
{
    return makeRefusal(kExitUsage, {std::move(line)});
}

// The site file: --config, or with --kiosk the installed one; its problems (the log spec's
// included) refuse the run with every problem's line. Fills in what the command line leaves open.
Resolved<void> resolveSite(RunOptions& o)
{
    std::string file = o.config;
    if (file.empty() && o.kiosk) {
        file = defaultSiteConfigPath().string();
        std::error_code ec;
        if (!std::filesystem::exists(file, ec)) {
            return tl::unexpected(
                    makeRefusal(kExitConfig,
                                {fmt::format("--kiosk: no site file at {}; install the "
                                             "package (it ships one) or pass --config "
                                             "FILE",
                                             file)},
                                {"", 0, "no site file"}));
        }
    }
    if (file.empty()) {
        return {};
    }
    auto site = loadSiteConfig(file);
    if (!site) {
        return tl::unexpected(makeRefusal(kExitConfig, {site.error().message}));
    }
    if (const std::string bad = checkLogSpec(site->config.logLevel); !bad.empty()) {
        site->problems.push_back({"log.level", site->config.lineOf("log.level"), bad});
    }
    if (!site->problems.empty()) {
        applySite(site->config, o); // the good values: where the service screen goes
        Refusal r = makeRefusal(kExitConfig, {}, site->problems.front());
        for (const auto& p : site->problems) {
            r.lines.push_back(formatProblem(file, p));
        }
        r.lines.push_back(fmt::format("{}: {} problem{}; 'replica config check {}' lists them",
                                      file, site->problems.size(),
                                      site->problems.size() == 1 ? "" : "s", file));
        return tl::unexpected(std::move(r));
    }
    o.site = site->config;
    applySite(*o.site, o);
    return {};
}

// The usage checks of the options as resolved, before anything is built. Fills in what the
// --site file's [sources] give.
Resolved<void> checkRunOptions(RunOptions& o)
{
    if (!o.sitePath.empty()) {
        auto site = readSiteSources(o.sitePath);
        if (!site) {
            return tl::unexpected(usage(site.error().message));
        }
        for (const auto& [kind, from] : *site) {
            if (o.sources[kind].empty()) {
                o.sources[kind] = from;
            }
        }
    }
    if (o.hal == "replay" && o.replayFile.empty()) {
        return tl::unexpected(usage("--hal replay needs --replay-file RECORDING (or "
                                    "run.replay_file in the site file)"));
    }
    if (o.hal == "replay" && o.replayFrom.empty()) {
        o.replayFrom = o.replayFile; // every device replays it unless told otherwise
    }
    if (o.hal == "live" && o.fast) {
        return tl::unexpected(
                usage("--fast needs the simulated sensors: live sensors run on the wall clock"));
    }
    if (auto choice = chooseDevices(o); !choice) {
        return tl::unexpected(usage(choice.error().message));
    }
    if (o.output != "headless" && o.output != "kms") {
        return tl::unexpected(usage(fmt::format("--output {}: expected 'headless' (no display) or "
                                                "'kms' (fullscreen on the console, no display "
                                                "server)",
                                                o.output)));
    }
    if (!o.record.empty() && !o.force) {
        // Refused before the run starts (the writer refuses it again, race-free): an existing
        // recording is evidence, and a link must not redirect the write.
        struct stat st {
        };
        if (::lstat(o.record.c_str(), &st) == 0 &&
            (S_ISLNK(st.st_mode) || (S_ISREG(st.st_mode) && st.st_size > 0))) {
            return tl::unexpected(usage(fmt::format(
                    "--record {}: {}", o.record,
                    S_ISLNK(st.st_mode) ? "is a symbolic link; name the file itself"
                                        : "already exists; pass --force to overwrite it, or "
                                          "name a new file")));
        }
    }
    if (o.output == "kms" && !o.size.empty()) {
        return tl::unexpected(usage(fmt::format("--size {}: on KMS the frame is the display "
                                                "mode's size; choose the mode with --kms-mode "
                                                "WIDTHxHEIGHT",
                                                o.size)));
    }
    return {};
}

// Whether the display profile is not a characterised panel: the nominal model, or a profile fitted
// from synthetic measurements (its description says so, as 'replica display fit --synthetic'
// writes it).
bool syntheticDisplay(const RunConfig& config)
{
    if (config.display == kUncalibratedDisplay) {
        return true;
    }
    // The bounded reader (a FIFO here hung the start before checkLoadable could refuse it).
    auto text = readInputFile(dataPath(config.display), kMaxJsonBytes, "display profile");
    if (!text || !checkJsonLimits(*text, config.display)) {
        return false; // checkLoadable reports an unreadable profile
    }
    try {
        const auto j = nlohmann::json::parse(*text);
        return j.value("description", std::string()).find("SYNTHETIC") != std::string::npos;
    } catch (const std::exception&) {
        return false; // checkLoadable reports an unreadable profile
    }
}

// A path stored relative to the data folder when it is inside it, so that a recording replays on
// another installation (replay opens only files inside the data folders); else 'outside'.
std::string relativeToData(const std::filesystem::path& abs, const std::filesystem::path& outside)
{
    std::error_code ec;
    const auto data = std::filesystem::weakly_canonical(dataDir(), ec);
    const auto rel = abs.lexically_relative(data);
    return !rel.empty() && *rel.begin() != ".." ? rel.string() : outside.string();
}

// The scene, the booth, the light and the display profile the options name.
Resolved<void> sceneAndDisplay(const RunOptions& o, RunConfig& config)
{
    if (!o.scene.empty()) {
        std::error_code ec;
        const auto abs = std::filesystem::weakly_canonical(o.scene, ec);
        config.sceneDir = relativeToData(abs, abs);
        if (!std::filesystem::is_regular_file(std::filesystem::path(o.scene) / "scene.json", ec)) {
            return tl::unexpected(
                    refuse(o, "--scene", "scene.dir", o.scene,
                           fmt::format("no scene.json there; name a scene folder "
                                       "such as {}",
                                       (dataDir() / "scenes" / "painting").string())));
        }
    }
    if (!o.booth.empty()) {
        std::error_code ec;
        const auto abs = std::filesystem::weakly_canonical(o.booth, ec);
        config.boothDir = relativeToData(abs, abs);
        if (!std::filesystem::is_regular_file(std::filesystem::path(o.booth) / "booth.json", ec)) {
            return tl::unexpected(refuse(
                    o, "--booth", "booth.dir", o.booth,
                    fmt::format("no booth.json there; name a booth folder such as 'replica booth "
                                "build' writes (docs/booth-capture.md), e.g. {}",
                                (dataDir() / "booth").string())));
        }
    }
    config.light = o.light;
    if (o.uncalibrated && !o.displayProfile.empty()) {
        return tl::unexpected(usage(fmt::format("--uncalibrated and --display-profile {} "
                                                "contradict each other: give one",
                                                o.displayProfile)));
    }
    if (o.uncalibrated) {
        config.display = kUncalibratedDisplay;
        logger("replica")->warn("--uncalibrated: driving a nominal sRGB-like {} cd/m^2 model, not "
                                "a characterised panel; colours on screen are not the surface's",
                                config.displayPeakCdM2);
    } else if (!o.displayProfile.empty()) {
        std::error_code ec;
        const auto given = std::filesystem::absolute(o.displayProfile, ec);
        config.display = relativeToData(std::filesystem::weakly_canonical(given, ec), given);
    }
    return {};
}

// The site file's stand, tracker pose and defaults; --site's calibrated tracker pose over them.
Resolved<void> siteGeometry(const RunOptions& o, RunConfig& config)
{
    auto log = logger("replica");
    if (o.site) {
        const SiteConfig& site = *o.site;
        config.booth = site.boothId;
        config.boothDimmer = site.boothDimmer;
        config.boothDimmerAuto = site.boothDimmerAuto;
        config.instrument.strayLightFraction = site.spectrometerStrayLight;
        config.instrument.wavelengthOffsetNm = site.spectrometerWavelengthOffsetNm;
        config.directCdM2PerY = site.spectrometerDirectCdM2PerY.value_or(config.directCdM2PerY);
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
            return tl::unexpected(makeRefusal(kExitFailure, {t.error().message}));
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
    return {};
}

// The run's rendering choices: basis, display inverse, planner, warm-up.
void renderChoices(const RunOptions& o, RunConfig& config)
{
    config.rateHz = o.rateHz;
    config.basis = !o.basis.empty() ? o.basis : std::string(kAdaptiveBasis);
    config.displayInverse = o.displayInverse;
    config.gamutMapping = o.gamut;
    config.viewingCompensation = !o.noViewing;
    config.flareSubtraction = !o.noFlare;
    config.falseColour = o.falseColour;
    // The planner in the loop: by default each lamp draws with the plan cached or shipped with
    // the scene (the fixed rules where there is none); --planner (or the site's planner = true)
    // also plans a scene that has none, --no-planner (planner = false) keeps the fixed rules.
    config.planner = !o.noPlanner;
    config.planIfMissing = o.planner;
    if (!o.planner && !o.noPlanner && o.site && o.site->renderPlannerSet) {
        config.planner = o.site->renderPlanner;
        config.planIfMissing = o.site->renderPlanner;
    }
    config.plannerCache = o.planCache;
    config.warmUp = !o.noWarmUp;
    config.warmUpAfterFirstFrame = true; // the first frame first (platform/output/pass_warm_up.h)
    config.errorProbeS = o.errorProbeS;
    config.tiltNodesDeg = o.tiltNodesDeg;
}

// A live run on a synthetic display profile: warned loudly, and refused by the kiosk unless the
// site file allows it.
Resolved<void> checkSynthetic(const RunOptions& o, const RunConfig& config)
{
    if (o.hal != "live" || !syntheticDisplay(config)) {
        return {};
    }
    auto log = logger("replica");
    for (int i = 0; i < 3; ++i) {
        log->warn("!!! LIVE RUN ON A SYNTHETIC DISPLAY PROFILE ({}): the colours on this screen "
                  "are not the surface's. Characterise the panel ('replica display fit') and set "
                  "display.profile in the site file. !!!",
                  config.display);
    }
    if (o.kiosk && !(o.site && o.site->allowSynthetic)) {
        const std::string what = "the kiosk refuses a live run on a synthetic display profile; "
                                 "set display.profile to the panel's profile, or "
                                 "display.allow_synthetic = true to accept wrong colours";
        if (o.site) {
            SiteProblem p{"display.allow_synthetic", o.site->lineOf("display.allow_synthetic"),
                          what};
            return tl::unexpected(makeRefusal(kExitConfig, {formatProblem(o.site->source, p)}, p));
        }
        return tl::unexpected(makeRefusal(kExitConfig, {"(no site file): " + what}));
    }
    return {};
}

// The run configuration the options ask for at frame size 'size'.
Resolved<void>
runConfigFromOptions(const RunOptions& o, std::pair<int, int> size, RunConfig& config)
{
    config.width = size.first;
    config.height = size.second;
    if (!o.panelSizeMm.empty()) {
        auto panel = parseSizeMm(o.panelSizeMm);
        if (!panel) {
            return tl::unexpected(usage(fmt::format("--panel-size-mm: {}", panel.error().message)));
        }
        config.stand.panelWidthM = panel->width / 1000.0;
        config.stand.panelHeightM = panel->height / 1000.0;
    }
    if (o.renderer != "booth") {
        // One renderer: the flat one's recordings replay on it (replica replay), and no new run
        // draws with it.
        return tl::unexpected(
                refuse(o, "--renderer", "scene.renderer", o.renderer,
                       o.renderer == "flat" ? "the flat renderer was removed; the booth pass draws "
                                              "every scene (give booth or leave it out); its "
                                              "recordings still replay"
                                            : "expected booth, the one renderer"));
    }
    renderChoices(o, config);
    if (auto ok = sceneAndDisplay(o, config); !ok) {
        return ok;
    }
    if (auto ok = siteGeometry(o, config); !ok) {
        return ok;
    }
    return checkSynthetic(o, config);
}

// The booth and the names and lines that refer to its lamps.
Resolved<void> checkBooth(const RunOptions& o, const RunConfig& config)
{
    if (config.booth != "replica-booth-1") {
        return tl::unexpected(refuse(o, "", "booth.id", config.booth,
                                     "unknown booth (this build has replica-booth-1)",
                                     kExitFailure));
    }
    auto booth = pipeline::scene::loadApplianceBooth(resolveSceneDir(config.boothDir),
                                                     dataDir().string());
    if (!booth) {
        return tl::unexpected(refuse(o, "--booth", "booth.dir", config.boothDir,
                                     booth.error().message, kExitFailure));
    }
    if (!config.defaultLamp.empty()) {
        const auto& lamps = booth->lights;
        if (std::none_of(lamps.begin(), lamps.end(),
                         [&](const auto& l) { return l.name == config.defaultLamp; })) {
            return tl::unexpected(refuse(
                    o, "", "defaults.lamp", config.defaultLamp,
                    fmt::format("not a lamp of booth '{}' ({})", config.booth, booth->names()),
                    kExitFailure));
        }
    }
    if (!o.live.lampGpio.empty()) {
        auto spec = hal::lamp::parseGpioLineSpec(o.live.lampGpio);
        if (!spec) {
            return tl::unexpected(refuse(o, "--lamp-gpio", "devices.lamp_gpio", o.live.lampGpio,
                                         spec.error().message, kExitFailure));
        }
        if (spec->offsets.size() != booth->lights.size()) {
            return tl::unexpected(refuse(
                    o, "--lamp-gpio", "devices.lamp_gpio", o.live.lampGpio,
                    fmt::format("{} lines for a booth with {} lamps; give one line per lamp, in "
                                "the booth's lamp order",
                                spec->offsets.size(), booth->lights.size()),
                    kExitFailure));
        }
    }
    return {};
}

// The files the run reads or writes beside the scene: the recording a replay run plays (read as
// the replay sources will read it, so that a file they would refuse is refused here, by config
// check too), and the kiosk's sessions folder, which must be a folder where it exists (a missing
// one is created at start; one that cannot be written is a fault the kiosk runs through, without
// recording, and says so).
Resolved<void> checkRunFiles(const RunOptions& o)
{
    if (o.hal == "replay" && !o.replayFile.empty()) {
        if (auto rec = recordings::readRecording(o.replayFile); !rec) {
            return tl::unexpected(refuse(o, "--replay-file", "run.replay_file", o.replayFile,
                                         rec.error().message, kExitFailure));
        }
    }
    const bool kioskRecording = o.kiosk && o.site && o.site->recordingEnabled && o.record.empty();
    std::error_code ec;
    if (kioskRecording && std::filesystem::exists(o.site->recordingDirectory, ec) &&
        !std::filesystem::is_directory(o.site->recordingDirectory, ec)) {
        return tl::unexpected(refuse(o, "", "recording.directory", o.site->recordingDirectory,
                                     "exists and is not a folder; name a folder for the "
                                     "sessions (created at start when missing)",
                                     kExitFailure));
    }
    return {};
}

// What the appliance will load (the display profile, the scene) and the devices will parse (the
// accelerometer's axes, the tracker's bind address), read and parsed now, opening no device.
Resolved<void> checkLoadable(const RunOptions& o, const RunConfig& config)
{
    if (auto ok = checkBooth(o, config); !ok) {
        return ok;
    }
    if (auto ok = checkRunFiles(o); !ok) {
        return ok;
    }
    if (config.display != kUncalibratedDisplay) {
        const std::string path = dataPath(config.display);
        auto read = readInputFile(path, kMaxJsonBytes, "display profile");
        auto model = read ? pipeline::display::profileFromJson(*read, path)
                          : Expected<pipeline::display::DisplayModel>(tl::unexpected(read.error()));
        if (!model) {
            const std::string what = !read && read.error().code == ErrorCode::NotFound
                                             ? missingDisplayProfileMessage(path)
                                             : model.error().message;
            return tl::unexpected(refuse(o, "--display-profile", "display.profile", config.display,
                                         what, kExitFailure));
        }
    }
    if (auto scene = pipeline::surface::loadScene(resolveSceneDir(config.sceneDir)); !scene) {
        return tl::unexpected(refuse(o, "--scene", "scene.dir", config.sceneDir,
                                     scene.error().message, kExitFailure));
    }
    if (auto axes = hal::accel::parseAxisMapping(o.live.accelAxes); !axes) {
        return tl::unexpected(refuse(o, "--accel-axes", "devices.accel_axes", o.live.accelAxes,
                                     axes.error().message, kExitFailure));
    }
    in_addr addr{};
    if (::inet_pton(AF_INET, o.live.trackerBind.c_str(), &addr) != 1) {
        return tl::unexpected(refuse(o, "--tracker-bind", "tracker.bind", o.live.trackerBind,
                                     "not an IPv4 address (e.g. 127.0.0.1, or 0.0.0.0 for every "
                                     "interface)",
                                     kExitFailure));
    }
    return {};
}

} // namespace

Refusal refuse(const RunOptions& o,
               const std::string& option,
               const std::string& siteKey,
               const std::string& value,
               const std::string& what,
               int cliCode)
{
    if (o.site && !siteKey.empty() && (option.empty() || !o.given.contains(option))) {
        SiteProblem p{siteKey, o.site->lineOf(siteKey), fmt::format("\"{}\": {}", value, what)};
        return makeRefusal(kExitConfig, {formatProblem(o.site->source, p)}, p);
    }
    return makeRefusal(cliCode, {fmt::format("{} {}: {}", option, value, what)});
}

Resolved<RunPlan> resolveRun(RunOptions o)
{
    if (o.kiosk && !o.given.contains("--frames")) {
        o.frames = 0; // the kiosk runs until it is stopped
    }
    const auto refused = [&o](Refusal r) {
        r.output = o.outputChoice;
        r.output.kind = o.output;
        r.size = o.size;
        r.siteFile = o.site ? o.site->source.string()
                            : (o.config.empty() && o.kiosk ? defaultSiteConfigPath().string()
                                                           : o.config);
        r.endless = o.frames == 0;
        return tl::unexpected(std::move(r));
    };
    if (auto ok = resolveSite(o); !ok) {
        return refused(ok.error());
    }
    if (auto ok = checkRunOptions(o); !ok) {
        return refused(ok.error());
    }
    RunPlan plan;
    const auto size = parseSize(o.size.empty() ? std::string("960x600") : o.size);
    if (!size) {
        return refused(refuse(o, "--size", "display.size", o.size,
                              fmt::format("expected WIDTHxHEIGHT, e.g. 960x600, each side 1-{} and "
                                          "at most {}:1",
                                          kMaxFrameSide, kMaxFrameAspect)));
    }
    plan.size = *size;
    if (auto ok = runConfigFromOptions(o, *size, plan.config); !ok) {
        return refused(ok.error());
    }
    if (auto ok = checkLoadable(o, plan.config); !ok) {
        return refused(ok.error());
    }
    plan.output = o.outputChoice;
    plan.output.kind = o.output;
    plan.output.frameFromMode = true;
    // The EDID's physical size only when neither the command line nor a site file gives one.
    plan.output.panelFromDisplay = o.panelSizeMm.empty() && !o.site;
    plan.options = std::move(o);
    return plan;
}

} // namespace replica::platform::run_cli
