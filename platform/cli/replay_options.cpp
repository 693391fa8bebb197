// 'replica replay's options.
#include <memory>

#include <platform/cli/commands.h>
#include <platform/cli/replay.h>
#include <platform/cli/replay_shown.h>
#include <platform/cli/wall_clock_time.h>

namespace replica::platform {

namespace {

// --reference, --mismatch-dir, --tolerance (the golden check) and --shown-tolerance,
// --compare-shown (what an older recording showed).
void addCheckOptions(CLI::App& cmd_, ReplayOptions& o)
{
    CLI::App* cmd = &cmd_;
    ReplayOptions* opts = &o;
    cmd->add_option("--reference", opts->reference,
                    "reference XYZ frames for --check (default: GOLDEN with .frames instead of "
                    ".json, if it exists): on a mismatch, ΔE00 of the first differing frame");
    cmd->add_option("--mismatch-dir", opts->mismatchDir,
                    "where --check writes the first differing frame and the difference image "
                    "(default: OUT.mismatch beside --digests OUT, else ./replay-mismatch)");
    cmd->add_option("--tolerance", opts->tolerance,
                    "with --check: pass when frames that differ from the golden bit for bit are "
                    "within DE00 (largest CIEDE2000 of any pixel) of the golden's reference "
                    "frames (GOLDEN.frames/ or --reference); say by how much")
            ->check(CLI::Range(0.0, 100.0));
    cmd->add_option("--shown-tolerance", opts->shownTolerance,
                    "an older recording (another render profile) is compared with what it "
                    "showed (its thumbnails, through its display model): pass when every "
                    "thumbnail's p95 ΔE00 is within this (default 2.0: two renders each within "
                    "the render budget of 1.0)")
            ->check(CLI::Range(0.0, 100.0));
    cmd->add_flag("--compare-shown", opts->compareShown,
                  "compare with what was shown (thumbnails) even when this build renders the "
                  "recording's profile bit for bit");
}

} // namespace

void registerReplayCommand(CLI::App& app, int& exitCode)
{
    auto opts = std::make_shared<ReplayOptions>();
    opts->shownTolerance = kShownToleranceDe00;
    auto* cmd = app.add_subcommand(
            "replay",
            "render a recording again through the replay HAL; the same recording always gives the "
            "same frames, bit for bit");
    cmd->add_option("file", opts->file, "recording (.mcap) written by 'replica run --record'")
            ->required();
    const CLI::Validator nonEmpty(
            [](std::string& s) { return s.empty() ? std::string("an empty name") : std::string(); },
            "", "PATH");
    cmd->add_option("--digests", opts->digests, "write one digest per frame to FILE (JSON)")
            ->check(nonEmpty);
    cmd->add_option("--data-root", opts->dataRoots,
                    "a folder besides the data folder whose files a recording may name (scene "
                    "folder, display profile); repeatable. Replay opens nothing else a recording "
                    "names");
    cmd->add_flag("--allow-undigested", opts->allowUndigested,
                  "replay a recording that holds no digest of its scene or display profile "
                  "(nothing then says the files are the ones recorded)");
    cmd->add_option("--check", opts->check,
                    "compare the frame digests with GOLDEN (a digests file); on the first "
                    "difference write that frame (PNG and XYZ), its ΔE00 difference image against "
                    "the reference frame, print ΔE00 statistics, and exit 1")
            ->check(nonEmpty);
    cmd->add_option("--snapshot", opts->snapshot, "write the last frame to FILE (PNG)");
    cmd->add_option("--save-frames", opts->saveFrames,
                    "write every frame's absolute XYZ to DIR/frame-NNNNNN.pfm (or .exr with "
                    "--save-format exr): reference frames for a golden");
    cmd->add_option("--output", opts->output,
                    "headless (no display) or kms (fullscreen: the recording's frame size as the "
                    "mode, or the preferred mode with the frame centred)")
            ->check(CLI::IsMember({"headless", "kms"}))
            ->capture_default_str();
    addKmsOptions(*cmd, opts->kms);
    addWarmUpOption(*cmd, opts->noWarmUp);
    cmd->add_flag("--hold", opts->hold,
                  "after the last frame, keep it on the display until SIGTERM or SIGINT (a still "
                  "for a demo, or for a screen check: with --from T --to T the display shows "
                  "exactly the frame at T)");
    const CLI::Validator timeArg(
            [](std::string& s) {
                auto a = parseTimeArg(s);
                return a ? std::string() : a.error().message;
            },
            "TIME", "");
    cmd->add_option("--from", opts->fromArg,
                    "replay only the frames from T on (the frames before are rendered first, "
                    "fast, since each frame depends on those before it). T is seconds of session "
                    "time (75.5), a time of day (14:32:05[.fff], in the local time zone: TZ), or "
                    "an ISO 8601 date and time (2026-12-06T14:32:05Z, ...+01:00, fractional "
                    "seconds allowed); a line says which session second a time maps to, and a "
                    "time outside the recording is refused (exit 2) with its span in both clocks")
            ->check(timeArg);
    cmd->add_option("--to", opts->toArg,
                    "... up to T (inclusive): seconds of session time, a time of day or ISO 8601, "
                    "as --from")
            ->check(timeArg);
    // One option under two names: --save-png is its older name, kept so that scripts using it
    // (deploy/boot-test once did) go on working.
    cmd->add_option("--frames-out,--save-png", opts->framesOut,
                    "write what the panel showed (its display counts) for every replayed frame "
                    "to DIR/frame-NNNNNN.png, NNNNNN the recording's frame number; --save-png "
                    "is the same option");
    cmd->add_flag("--json", opts->json,
                  "print a JSON summary (frames, slice, check result with ΔE00, display "
                  "digests) on standard output instead of the text lines");
    cmd->add_flag("--progress", opts->progress,
                  "progress lines on standard error (at most one a second) even when it is not "
                  "a terminal; on a terminal they are on by default");
    cmd->add_flag("--no-progress", opts->noProgress, "no progress lines");
    cmd->add_option("--save-only", opts->saveOnly,
                    "with --save-frames: only these frames, e.g. 0,75,149");
    cmd->add_option("--save-format", opts->saveFormat,
                    "with --save-frames: pfm (32-bit float) or exr (half float, ZIP: small "
                    "enough to commit)")
            ->check(CLI::IsMember({"pfm", "exr"}))
            ->capture_default_str();
    cmd->add_option("--clock", opts->clock,
                    "recorded: at the recorded pace; fast: as fast as possible; step: one frame "
                    "per line "
                    "on standard input")
            ->check(CLI::IsMember({"recorded", "fast", "step"}))
            ->capture_default_str();
    cmd->add_flag("--reprocess", opts->reprocess,
                  "raw in, processed out: re-derive the tracker's and accelerometer's samples "
                  "from the raw inputs recorded beside them (format 5) with today's processing "
                  "code, so a processing fix applies to old field recordings; samples without "
                  "raw inputs stay as recorded");
    cmd->add_option("--tracker-axes", opts->trackerAxes,
                    "with --reprocess: HID tracker axes to use instead of the recorded ones "
                    "(as 'run --tracker-axes', e.g. x,-y,z)");
    cmd->add_option("--accel-axes", opts->accelAxes,
                    "with --reprocess: accelerometer mounting to use instead of the recorded one "
                    "(as 'run --accel-axes', e.g. -y,x,z)");
    addCheckOptions(*cmd, *opts);
    cmd->callback([opts, &exitCode] { exitCode = replayMain(*opts); });
}

} // namespace replica::platform
