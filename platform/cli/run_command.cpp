// 'replica run': the appliance's main job, the fixed-rate loop on the chosen sensors and output.
#include <chrono>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <optional>

#include <fmt/format.h>

#include <pipeline/base/data_dir.h>
#include <platform/appliance.h>
#include <platform/cli/commands.h>
#include <platform/cli/frame_outputs.h>
#include <platform/logging.h>
#include <platform/loop/frame_loop.h>

namespace replica::platform {
namespace {

struct RunOptions {
    std::string hal = "sim";
    std::string output = "headless";
    std::uint64_t frames = 180;
    std::string size = "960x600";
    double rateHz = 60.0;
    std::string record;
    std::string digests;
    std::string snapshot;
    bool fast = false;
    std::string scene;
    std::string renderer = "booth";
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
    if (o.hal != "sim") {
        log->error("--hal {}: only the built-in simulated sensors ('sim') are in this build; live "
                   "drivers are not yet",
                   o.hal);
        return kExitUsage;
    }
    if (o.output != "headless") {
        log->error("--output {}: only 'headless' output is in this build; KMS output is not yet",
                   o.output);
        return kExitUsage;
    }
    const auto size = parseSize(o.size);
    if (!size) {
        log->error("--size {}: expected WIDTHxHEIGHT, e.g. 960x600", o.size);
        return kExitUsage;
    }
    RunConfig config;
    config.width = size->first;
    config.height = size->second;
    config.rateHz = o.rateHz;
    config.renderer = o.renderer;
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

    auto appliance = buildAppliance(config);
    if (!appliance) {
        log->error("{}", appliance.error().message);
        return kExitFailure;
    }
    auto sources = makeSimSources(**appliance);
    if (!sources) {
        log->error("{}", sources.error().message);
        return kExitFailure;
    }
    log->info("hal: spectrometer={} [{} {}], tracker={} [{} {}], accel={} [{} {}]; output={}; "
              "renderer={} on {}; {}x{} at {} Hz",
              hal::toString(sources->spectrometer->info().kind),
              sources->spectrometer->info().model, sources->spectrometer->info().serial,
              hal::toString(sources->tracker->info().kind), sources->tracker->info().model,
              sources->tracker->info().serial, hal::toString(sources->accel->info().kind),
              sources->accel->info().model, sources->accel->info().serial,
              (*appliance)->output->name(), (*appliance)->renderer->description(),
              (*appliance)->output->glRenderer(), config.width, config.height, config.rateHz);

    std::unique_ptr<recordings::RecordingWriter> recorder;
    if (!o.record.empty()) {
        recordings::SessionInfo session;
        session.softwareVersion = std::string("replica ") + REPLICA_VERSION;
        // The configuration as built: it names the scene folder and its digest.
        const RunConfig& built = (*appliance)->config;
        session.configJson = built.toJson();
        session.boothModel = built.booth;
        session.scene = built.scene;
        session.displayProfile = built.display;
        session.wallClockStartNs = std::chrono::duration_cast<std::chrono::nanoseconds>(
                                           std::chrono::system_clock::now().time_since_epoch())
                                           .count();
        session.spectrometer = sources->spectrometer->info();
        session.tracker = sources->tracker->info();
        session.accel = sources->accel->info();
        auto w = recordings::RecordingWriter::create(o.record, session);
        if (!w) {
            log->error("{}", w.error().message);
            return kExitFailure;
        }
        recorder = std::move(*w);
    }

    FrameOutputs outputs(!o.digests.empty(), !o.snapshot.empty());
    const auto plan = fixedRatePlan(config.periodNs(), o.frames);
    auto stats = runFrames(**appliance, *sources, plan, o.fast ? Pacing::Fast : Pacing::Realtime,
                           recorder.get(), outputs.readback(), outputs.callback());
    if (!stats) {
        log->error("{}", stats.error().message);
        return kExitFailure;
    }
    int code = kExitOk;
    if (recorder) {
        if (auto closed = recorder->close(); !closed) {
            log->error("{}", closed.error().message);
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
    log->info("{} frames; dropped samples: spectrometer {}, tracker {}, accel {}; late frames {}",
              stats->frames, stats->droppedSpectra, stats->droppedPoses, stats->droppedAccel,
              stats->lateFrames);
    return code;
}

} // namespace

void registerRunCommand(CLI::App& app, int& exitCode)
{
    auto opts = std::make_shared<RunOptions>();
    auto* cmd =
            app.add_subcommand("run", "run the appliance: sensors -> scene -> render -> output at "
                                      "a fixed rate");
    cmd->add_option("--hal", opts->hal, "sensor sources: sim (built-in simulated sensors)")
            ->capture_default_str();
    cmd->add_option("--output", opts->output, "frame output: headless (surfaceless EGL)")
            ->capture_default_str();
    cmd->add_option("--frames", opts->frames, "number of frames to run")->capture_default_str();
    cmd->add_option("--size", opts->size, "frame size WIDTHxHEIGHT")->capture_default_str();
    cmd->add_option("--rate", opts->rateHz, "frame rate (Hz)")
            ->check(CLI::Range(1.0, 1000.0))
            ->capture_default_str();
    cmd->add_option("--record", opts->record, "write every sensor sample and frame input to FILE");
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
    cmd->add_flag("--fast", opts->fast,
                  "do not wait for each tick's wall-clock time (same frames, rendered as fast as "
                  "possible)");
    cmd->callback([opts, &exitCode] { exitCode = runMain(*opts); });
}

} // namespace replica::platform
