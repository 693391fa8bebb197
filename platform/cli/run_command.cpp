// 'replica run': the appliance's main job, the fixed-rate loop on the chosen sensors and output.
#include <chrono>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <optional>

#include <fmt/format.h>

#include <pipeline/base/data_dir.h>
#include <pipeline/spectral/representation_catalogue.h>
#include <platform/appliance.h>
#include <platform/cli/commands.h>
#include <platform/cli/frame_outputs.h>
#include <platform/live_sources.h>
#include <platform/logging.h>
#include <platform/loop/frame_loop.h>

namespace replica::platform {
namespace {

struct RunOptions {
    std::string hal = "sim";
    std::string lampSelector = "none"; // sim only: none, sim, sim-miswired
    std::string output = "headless";
    std::uint64_t frames = 180;
    std::string size; // headless: 960x600 when not given; kms: the mode's size
    std::string panelSizeMm;
    double rateHz = 60.0;
    std::string record;
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
    LiveOptions live;
    OutputChoice outputChoice;
};

std::optional<std::pair<int, int>> parseSize(const std::string& s)
{
    int w = 0;
    int h = 0;
    char x = 0;
    char extra = 0;
    if (std::sscanf(s.c_str(), "%d%c%d%c", &w, &x, &h, &extra) != 3 || (x != 'x' && x != 'X') ||
        w <= 0 || h <= 0 || w > 16384 || h > 16384) {
        return std::nullopt;
    }
    return std::make_pair(w, h);
}

int runMain(const RunOptions& o)
{
    auto log = logger("replica");
    if (o.hal != "sim" && o.hal != "live") {
        log->error("--hal {}: expected 'sim' (built-in simulated sensors) or 'live' (USB2000+, "
                   "opentrack, IIO accelerometer)",
                   o.hal);
        return kExitUsage;
    }
    if (o.hal == "live" && o.fast) {
        log->error("--fast needs the simulated sensors: live sensors run on the wall clock");
        return kExitUsage;
    }
    if (o.output != "headless" && o.output != "kms") {
        log->error("--output {}: expected 'headless' (no display) or 'kms' (fullscreen on the "
                   "console, no display server)",
                   o.output);
        return kExitUsage;
    }
    if (o.output == "kms" && !o.size.empty()) {
        log->error("--size {}: on KMS the frame is the display mode's size; choose the mode with "
                   "--kms-mode WIDTHxHEIGHT",
                   o.size);
        return kExitUsage;
    }
    const auto size = parseSize(o.size.empty() ? std::string("960x600") : o.size);
    if (!size) {
        log->error("--size {}: expected WIDTHxHEIGHT, e.g. 960x600", o.size);
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
        if (!std::filesystem::is_regular_file(abs / "scene.json")) {
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
        config.display = std::filesystem::absolute(o.displayProfile).string();
    }
    config.displayInverse = o.displayInverse;
    config.gamutMapping = o.gamut;
    config.viewingCompensation = !o.noViewing;
    config.flareSubtraction = !o.noFlare;
    config.falseColour = o.falseColour;

    OutputChoice outputChoice = o.outputChoice;
    outputChoice.kind = o.output;
    outputChoice.frameFromMode = true;
    outputChoice.panelFromDisplay = o.panelSizeMm.empty();
    auto appliance = buildAppliance(config, outputChoice);
    if (!appliance) {
        log->error("{}", appliance.error().message);
        return kExitFailure;
    }
    // Live devices stamp samples on this clock; the loop's ticks start with it (within the few
    // milliseconds between here and the first tick, which only delays samples by that much).
    hal::SteadyClock liveClock;
    if (o.hal == "live" && o.lampSelector != "none") {
        log->error("--lamp-selector {} is for --hal sim; a live booth's switch is read with "
                   "--lamp-gpio CHIP:OFFSETS",
                   o.lampSelector);
        return kExitUsage;
    }
    if (o.hal == "sim" && !o.live.lampGpio.empty()) {
        log->error("--lamp-gpio needs --hal live; the simulated booth's switch is "
                   "--lamp-selector sim");
        return kExitUsage;
    }
    auto sources = o.hal == "live"
                           ? makeLiveSources(liveClock, o.live, (*appliance)->booth.lamps.size())
                           : makeSimSources(**appliance, o.lampSelector);
    if (!sources) {
        log->error("{}", sources.error().message);
        return kExitFailure;
    }
    log->info("hal: spectrometer={} [{} {}], tracker={} [{} {}], accel={} [{} {}]; output={}; "
              "renderer={} on {}; {}x{} at {} Hz; display {}",
              hal::toString(sources->spectrometer->info().kind),
              sources->spectrometer->info().model, sources->spectrometer->info().serial,
              hal::toString(sources->tracker->info().kind), sources->tracker->info().model,
              sources->tracker->info().serial, hal::toString(sources->accel->info().kind),
              sources->accel->info().model, sources->accel->info().serial,
              (*appliance)->output->name(), (*appliance)->renderer->description(),
              (*appliance)->output->glRenderer(), (*appliance)->config.width,
              (*appliance)->config.height, config.rateHz, (*appliance)->displayProfileId);

    std::unique_ptr<recordings::RecordingWriter> recorder;
    bool recordFailed = false;
    if (!o.record.empty()) {
        recordings::SessionInfo session;
        session.softwareVersion = std::string("replica ") + REPLICA_VERSION;
        // The configuration as built: the scene folder and digest, the display profile's digest.
        const RunConfig& built = (*appliance)->config;
        session.configJson = built.toJson();
        session.boothModel = built.booth;
        session.scene = built.scene;
        session.displayProfile = (*appliance)->displayProfileId;
        session.wallClockStartNs = std::chrono::duration_cast<std::chrono::nanoseconds>(
                                           std::chrono::system_clock::now().time_since_epoch())
                                           .count();
        session.spectrometer = sources->spectrometer->info();
        session.tracker = sources->tracker->info();
        session.accel = sources->accel->info();
        if (sources->lampSelector) {
            session.lampSelector = sources->lampSelector->info();
        }
        recordings::WriterOptions options;
        options.flushInterval = std::chrono::milliseconds(o.recordFlushMs);
        // Called once from the writer thread; the loop keeps displaying without the recording.
        options.onError = [log](const Error& e) {
            log->error("{}; recording stopped, display continues", e.message);
        };
        auto w = recordings::RecordingWriter::create(o.record, session, options);
        if (!w) {
            // The appliance still displays; the run reports failure at the end.
            log->error("{}; running without recording", w.error().message);
            recordFailed = true;
        } else {
            recorder = std::move(*w);
        }
    }

    FrameOutputs outputs(!o.digests.empty(), !o.snapshot.empty());
    // --frames 0: run until SIGINT/SIGTERM (the kiosk), closing the recording properly.
    installStopSignals();
    const TickSource ticks =
            o.frames == 0 ? endlessTicks(config.periodNs())
                          : TickSource([plan = fixedRatePlan(config.periodNs(), o.frames),
                                        k = std::size_t{0}]() mutable -> std::optional<TickPlan> {
                                if (k >= plan.size()) {
                                    return std::nullopt;
                                }
                                return plan[k++];
                            });
    // Scan-out needs the display pixels of every frame, digests or not.
    auto readback = outputs.readback();
    if ((*appliance)->output->needsPixels() && readback == pipeline::render::Readback::None) {
        readback = pipeline::render::Readback::Display;
    }
    auto stats = runFrames(**appliance, *sources, ticks, o.fast ? Pacing::Fast : Pacing::Realtime,
                           recorder.get(), readback, outputs.callback());
    if (!stats) {
        log->error("{}", stats.error().message);
        return kExitFailure;
    }
    int code = recordFailed ? kExitFailure : kExitOk;
    if (recorder) {
        if (auto closed = recorder->close(); !closed) {
            // Already logged by onError when it happened; say where the run stands.
            log->warn("recording {} is incomplete; 'replica recover' rebuilds what was written",
                      o.record);
            code = kExitFailure;
        } else {
            fmt::print("recording: {}\n", o.record);
        }
    }
    if (auto ok = outputs.finish(o.digests, o.snapshot); !ok) {
        log->error("{}", ok.error().message);
        return kExitFailure;
    }
    if (!o.digests.empty()) {
        fmt::print("digests: {}\n", o.digests);
    }
    if (!o.snapshot.empty()) {
        fmt::print("snapshot: {}\n", o.snapshot);
    }
    if (sources->lampSelector) {
        log->info("lamp selector {} [{} {}]: overruled by the spectrometer {} times",
                  hal::toString(sources->lampSelector->info().kind),
                  sources->lampSelector->info().model, sources->lampSelector->info().serial,
                  (*appliance)->updater->lampArbiter().overruled());
    }
    log->info("{} frames; dropped samples: spectrometer {}, tracker {}, accel {}, lamp selector "
              "{}; late frames {}; out of gamut: mean {:.4f}, max {:.4f} of pixels",
              stats->frames, stats->droppedSpectra, stats->droppedPoses, stats->droppedAccel,
              stats->droppedLamp, stats->lateFrames, stats->meanOutOfGamutFraction(),
              stats->maxOutOfGamutFraction);
    const FrameTimes& t = stats->frameTimes;
    const double periodMs = 1000.0 / o.rateHz;
    // --digests reads every frame back as float XYZ and hashes it byte by byte (FNV-1a, the
    // format's), inside each frame's time: about 19 ms at 960x600 on a 2-core machine, which the
    // kiosk never pays. Said so that the figure is not taken for the appliance's.
    log->info("frame time: mean {:.1f} ms ({:.0f} frames/s), 95th percentile {:.1f}, max {:.1f}; "
              "{} of {} frames took the whole {:.1f} ms period or more{}",
              t.meanMs(), t.meanMs() > 0.0 ? 1000.0 / t.meanMs() : 0.0, t.percentileMs(0.95),
              t.maxMs(), t.atLeast(periodMs), t.count(), periodMs,
              o.digests.empty() ? ""
                                : " (including --digests: each frame read back as XYZ and "
                                  "hashed, which a run without it does not do)");
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
    cmd->add_option("--hal", opts->hal,
                    "sensor sources: sim (built-in simulated sensors) or live (USB2000+ over "
                    "libusb, opentrack UDP head poses, IIO accelerometer)")
            ->capture_default_str();
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
    cmd->add_option("--lamp-selector", opts->lampSelector,
                    "sim: none, sim (a switch that follows the simulated lamps, with contact "
                    "bounce) or sim-miswired (its lines for lamps 1 and 2 swapped)")
            ->check(CLI::IsMember({"none", "sim", "sim-miswired"}))
            ->capture_default_str();
    cmd->add_option("--output", opts->output,
                    "frame output: headless (surfaceless EGL) or kms (fullscreen scan-out)")
            ->capture_default_str();
    addKmsOptions(*cmd, opts->outputChoice.kms);
    cmd->add_option("--frames", opts->frames,
                    "number of frames to run; 0 = until SIGINT/SIGTERM (the kiosk)")
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
    cmd->add_option("--record-flush-ms", opts->recordFlushMs,
                    "close and sync the recording's open chunk at least this often (ms): a power "
                    "cut loses at most about this much")
            ->check(CLI::Range(10, 10000))
            ->capture_default_str();
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
    cmd->add_flag("--false-colour", opts->falseColour,
                  "field-staff overlay: stripe out-of-gamut pixels (magenta: chroma, cyan: above "
                  "peak, blue: below black)");
    cmd->callback([opts, &exitCode] { exitCode = runMain(*opts); });
}

} // namespace replica::platform
