// 'replica replay': feeds a recording back through the replay HAL and renders the same frames.
#include <filesystem>

#include <fmt/format.h>

#include <platform/appliance.h>
#include <platform/cli/commands.h>
#include <platform/cli/frame_outputs.h>
#include <platform/logging.h>
#include <platform/loop/frame_loop.h>

namespace replica::platform {
namespace {

struct ReplayOptions {
    std::string file;
    std::string digests;
    std::string check;
    std::string snapshot;
    std::string clock = "fast";
};

int replayMain(const ReplayOptions& o)
{
    auto log = logger("replica");
    auto recording = recordings::readRecording(o.file);
    if (!recording) {
        log->error("{}", recording.error().message);
        return kExitFailure;
    }
    auto config = RunConfig::fromJson(recording->session.configJson);
    if (!config) {
        log->error("{}: {}", o.file, config.error().message);
        return kExitFailure;
    }
    auto appliance = buildAppliance(*config);
    if (!appliance) {
        log->error("{}", appliance.error().message);
        return kExitFailure;
    }
    Sources sources = makeReplaySources(*recording);
    const Pacing pacing = o.clock == "recorded" ? Pacing::Realtime
                          : o.clock == "step"   ? Pacing::Step
                                                : Pacing::Fast;
    log->info("replay {}: {} frames, {} spectra, {} poses, {} accel samples (recorded by {}); "
              "clock={}; renderer={} on {}; {}x{}",
              o.file, recording->frames.size(), recording->spectra.size(), recording->poses.size(),
              recording->accel.size(), recording->session.softwareVersion, o.clock,
              (*appliance)->renderer->description(), (*appliance)->output->glRenderer(),
              config->width, config->height);

    FrameOutputs outputs(!o.digests.empty() || !o.check.empty(), !o.snapshot.empty());
    auto stats = runFrames(**appliance, sources, replayPlan(recording->frames), pacing, nullptr,
                           outputs.readback(), outputs.callback());
    if (!stats) {
        log->error("{}", stats.error().message);
        return kExitFailure;
    }
    if (auto ok = outputs.finish(o.digests, o.snapshot); !ok) {
        log->error("{}", ok.error().message);
        return kExitFailure;
    }
    if (!o.digests.empty()) {
        fmt::print("digests: {}\n", o.digests);
    }
    if (!o.check.empty()) {
        auto golden = readDigests(o.check);
        if (!golden) {
            log->error("{}", golden.error().message);
            return kExitFailure;
        }
        const long diff = firstDifference(*golden, outputs.digests());
        if (diff >= 0) {
            log->error("{}: frame {} differs from the golden digests in {} ({} golden frames, {} "
                       "replayed)",
                       o.file, diff, o.check, golden->size(), outputs.digests().size());
            return kExitFailure;
        }
        fmt::print("check: all {} frames match {}\n", golden->size(), o.check);
    }
    return stats->replayMismatches > 0 ? kExitLossy : kExitOk;
}

} // namespace

void registerReplayCommand(CLI::App& app, int& exitCode)
{
    auto opts = std::make_shared<ReplayOptions>();
    auto* cmd = app.add_subcommand(
            "replay",
            "render a recording again through the replay HAL; the same recording always gives the "
            "same frames, bit for bit");
    cmd->add_option("file", opts->file, "recording (.mcap) written by 'replica run --record'")
            ->required();
    cmd->add_option("--digests", opts->digests, "write one digest per frame to FILE (JSON)");
    cmd->add_option("--check", opts->check,
                    "compare the frame digests with GOLDEN (a digests file); exit 1 on the first "
                    "difference");
    cmd->add_option("--snapshot", opts->snapshot, "write the last frame to FILE (PNG)");
    cmd->add_option("--clock", opts->clock,
                    "recorded: at the recorded pace; fast: as fast as possible; step: one frame "
                    "per line "
                    "on standard input")
            ->check(CLI::IsMember({"recorded", "fast", "step"}))
            ->capture_default_str();
    cmd->callback([opts, &exitCode] { exitCode = replayMain(*opts); });
}

} // namespace replica::platform
