// 'replica replay': feeds a recording back through the replay HAL and renders the same frames.
// The steps in order: read and check the recording, build its appliance, run the slice's frames
// through the checks, report (replay.h names the pieces).
#include <algorithm>
#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <optional>
#include <variant>

#include <fmt/format.h>
#include <nlohmann/json.hpp>
#include <pthread.h>
#include <unistd.h>

#include <pipeline/display/icc_profile.h>
#include <pipeline/render/render_profile.h>
#include <platform/appliance.h>
#include <platform/cli/commands.h>
#include <platform/cli/frame_outputs.h>
#include <platform/cli/loop_summary.h>
#include <platform/cli/replay.h>
#include <platform/cli/replay_shown.h>
#include <platform/cli/replay_worker.h>
#include <platform/image/png_metadata.h>
#include <platform/image/png_writer.h>
#include <platform/image/xyz_frame.h>
#include <platform/logging.h>

namespace replica::platform {
namespace {

// A recording and its run configuration, read and checked: what replay renders.
struct LoadedReplay {
    recordings::Recording recording;
    RunConfig config;
    std::optional<ReprocessReport> reprocessed;
};

// Reads the recording and its configuration and checks what they name and hold; on failure the
// exit code, the message logged.
std::variant<LoadedReplay, int> loadReplay(const ReplayOptions& o)
{
    auto log = logger("replica");
    auto recording = recordings::readRecording(o.file);
    if (!recording) {
        log->error("{}", recording.error().message);
        return kExitFailure;
    }
    std::vector<std::string> configWarnings;
    auto config = RunConfig::fromJson(recording->session.configJson, &configWarnings);
    for (const auto& w : configWarnings) {
        log->warn("{}: {}", o.file, w);
    }
    if (!config) {
        log->error("{}: {}", o.file, config.error().message);
        return kExitFailure;
    }
    // The recording is untrusted: it names files only inside the data folders, with digests.
    const std::vector<std::filesystem::path> roots(o.dataRoots.begin(), o.dataRoots.end());
    if (auto ok = checkRecordedReferences(*config, roots, o.allowUndigested); !ok) {
        log->error("{}: {}", o.file, ok.error().message);
        return kExitFailure;
    }
    if ((o.trackerAxes || o.accelAxes) && !o.reprocess) {
        log->error("--tracker-axes and --accel-axes change how raw inputs are processed: they "
                   "need --reprocess");
        return kExitUsage;
    }
    LoadedReplay loaded{std::move(*recording), std::move(*config), std::nullopt};
    if (o.reprocess) {
        auto r = reprocess(loaded.recording, ReprocessOptions{o.trackerAxes, o.accelAxes});
        if (!r) {
            log->error("{}: --reprocess: {}", o.file, r.error().message);
            return kExitFailure;
        }
        loaded.reprocessed = *r;
        if (r->posesNonFinite + r->accelNonFinite > 0) {
            log->warn(
                    "{}: --reprocess: {} poses and {} accelerometer samples came out not finite "
                    "(a recorded scale or raw value out of range{}{}); the loop ignores them as "
                    "it does a device's NaN",
                    o.file, r->posesNonFinite, r->accelNonFinite,
                    r->accelFirstNonFinite.empty() ? "" : "; the first: ", r->accelFirstNonFinite);
        }
        if (r->posesReprocessed + r->accelReprocessed == 0) {
            log->warn("{}: --reprocess: the recording holds no raw inputs of the tracker or "
                      "accelerometer (format {}; they are recorded from format 5 on, from live "
                      "devices and the simulated accelerometer): replaying their recorded "
                      "samples",
                      o.file, loaded.recording.formatVersion);
        }
    }
    // readRecording refused frames out of tick order (recordings/message_decoder.cpp), as inspect
    // and recover do.
    return loaded;
}

// The appliance the recording's configuration describes, on the output the options ask for.
Expected<std::unique_ptr<Appliance>> buildReplayAppliance(const ReplayOptions& o, RunConfig& config)
{
    OutputChoice outputChoice;
    outputChoice.kind = o.output;
    outputChoice.kms = o.kms;
    if (o.output == "kms" && o.kms.mode.empty()) {
        // The recording's frame size is the mode to ask for; the preferred one if there is none
        // of that size (the frame is then centred or cropped).
        outputChoice.kms.mode = fmt::format("{}x{}", config.width, config.height);
        outputChoice.kms.modeOrPreferred = true;
    }
    config.warmUp = !o.noWarmUp; // not recorded: the frames are the same either way
    return buildAppliance(config, outputChoice);
}

// Everything a replayed frame goes through, and what the report needs of them.
struct ReplayRun {
    ReplayRun(const ReplayOptions& options,
              const ReplaySlice& s,
              FrameOutputs& out,
              GoldenCheck& g,
              ShownDigests& digests,
              std::optional<ShownComparison>& thumbnails,
              std::optional<std::vector<std::uint64_t>> only)
        : o(options), slice(s), outputs(out), golden(g), shownDigests(digests), shown(thumbnails),
          saveOnly(std::move(only))
    {}

    const ReplayOptions& o;
    const ReplaySlice& slice;
    FrameOutputs& outputs;
    GoldenCheck& golden;
    ShownDigests& shownDigests;
    std::optional<ShownComparison>& shown;
    std::optional<std::vector<std::uint64_t>> saveOnly;
    std::optional<Error> error;      // written by the checks' thread
    std::atomic<bool> failed{false}; // the same, read by the frame thread
    std::uint64_t framesWritten = 0;
    // --frames-out's PNGs: the display profile they are in (empty: sRGB) and the recording's
    // wall-clock start (png_metadata.h).
    std::vector<std::uint8_t> icc;
    std::string iccName;
    std::int64_t wallStartNs = 0;
    std::uint64_t done = 0;
    std::chrono::steady_clock::time_point start = std::chrono::steady_clock::now();
    std::chrono::steady_clock::time_point lastProgress = start;
    bool showProgress = false;

    // The PNGs' colour space (the display profile) and time (png_metadata.h).
    void tagPngs(const pipeline::display::DisplayModel& model, std::int64_t wallStart)
    {
        if (auto profile = pipeline::display::iccProfileBytes(model); profile) {
            icc = std::move(*profile);
            iccName = model.name;
        } else {
            logger("replica")->warn("the PNGs are tagged sRGB: {}", profile.error().message);
        }
        wallStartNs = wallStart;
        outputs.tagSnapshot(icc, iccName, wallStartNs);
    }

    void progress(const recordings::FrameRecord& f)
    {
        const auto now = std::chrono::steady_clock::now();
        if (now - lastProgress < std::chrono::seconds(1) && done != slice.plan.size()) {
            return;
        }
        lastProgress = now;
        const double el = std::chrono::duration<double>(now - start).count();
        const double rate = el > 0.0 ? static_cast<double>(done) / el : 0.0;
        const double left = rate > 0.0 ? static_cast<double>(slice.plan.size() - done) / rate : 0.0;
        std::fprintf(stderr,
                     "replay: frame %llu (%llu of %zu, %.0f%%), session time %.1f s, %.1f "
                     "frames/s, %.0f s left%s\n",
                     static_cast<unsigned long long>(f.frameIndex),
                     static_cast<unsigned long long>(done), slice.plan.size(),
                     100.0 * static_cast<double>(done) /
                             static_cast<double>(std::max<std::size_t>(slice.plan.size(), 1)),
                     static_cast<double>(f.tickNs) * 1e-9, rate, left,
                     slice.contains(f.tickNs) ? "" : " (before the slice)");
    }

    Expected<void> save(const recordings::FrameRecord& f,
                        const pipeline::render::RenderedFrame& image)
    {
        const auto frameNo = static_cast<long>(f.frameIndex);
        if (!o.framesOut.empty()) {
            const PngMetadata meta =
                    shownFrameMetadata(icc, iccName, wallStartNs, f.tickNs, f.frameIndex);
            if (auto ok = writePng(framePath(o.framesOut, frameNo, ".png"), image.width,
                                   image.height, image.rgba, &meta);
                !ok) {
                return ok;
            }
            ++framesWritten;
        }
        const bool listed = !saveOnly || std::find(saveOnly->begin(), saveOnly->end(),
                                                   f.frameIndex) != saveOnly->end();
        if (!o.saveFrames.empty() && listed) {
            return writeXyzFrame(
                    framePath(o.saveFrames, frameNo, o.saveFormat == "exr" ? ".exr" : ".pfm"),
                    {image.width, image.height, image.xyz});
        }
        return {};
    }

    // On the frame thread: counts the frame (the progress line) and says whether it goes to the
    // checks: a frame of the slice, while none of them failed.
    bool wanted(const recordings::FrameRecord& f)
    {
        ++done;
        if (showProgress) {
            progress(f);
        }
        return slice.contains(f.tickNs) && !failed.load(std::memory_order_relaxed);
    }

    // On the checks' thread (replay_worker.h), the frames in order: digests, what was shown, the
    // frames written, the golden.
    void check(const recordings::FrameRecord& f, const pipeline::render::RenderedFrame& image)
    {
        if (error) {
            return;
        }
        outputs.add(f, image);
        // The recorded display digest is XXH3 of the display values: the digests' own when they
        // hash with it.
        std::optional<std::uint64_t> rgbaHash;
        if (outputs.hash() == DigestHash::Xxh3_64 && !outputs.digests().empty() &&
            outputs.digests().back().frameIndex == f.frameIndex) {
            rgbaHash = outputs.digests().back().rgba;
        }
        shownDigests.frame(f.frameIndex, image.rgba, rgbaHash);
        Expected<void> ok = save(f, image);
        if (ok && shown) {
            ok = shown->add(f.frameIndex, f.tickNs, image.width, image.height, image.rgba);
        }
        if (ok && golden.active()) {
            ok = golden.frame(static_cast<long>(f.frameIndex), image, outputs.digests().back());
        }
        if (!ok) {
            error = ok.error();
            failed.store(true, std::memory_order_relaxed);
        }
    }
};

// Creates the folders the options write frames into.
Expected<void> makeFrameDirs(const ReplayOptions& o)
{
    for (const auto* dir : {&o.saveFrames, &o.framesOut}) {
        std::error_code ec;
        if (!dir->empty() && (std::filesystem::create_directories(*dir, ec), ec)) {
            return makeError(ErrorCode::Io,
                             fmt::format("{}: cannot create directory: {}", *dir, ec.message()));
        }
    }
    return {};
}

// The comparison with what was shown: its verdict into summary["shown_check"] and its lines; the
// exit code it makes.
int reportShown(const ReplayOptions& o,
                const ShownComparison& shown,
                nlohmann::json& summary,
                int code,
                const std::function<void(const std::string&)>& say)
{
    summary["shown_check"] = shown.json();
    if (shown.thumbnails() == 0 || shown.measured().empty()) {
        say(fmt::format("shown: the recording holds no thumbnail of a replayed frame (format {} "
                        "records them from 4 on): nothing of what was shown to compare",
                        summary.value("format_version", 0)));
        return code;
    }
    std::string worst;
    for (const auto& m : shown.worst(3)) {
        worst += fmt::format("{}frame {} (p95 {:.2f}, max {:.2f})", worst.empty() ? "" : ", ",
                             m.frame, m.stats.p95, m.stats.max);
    }
    const auto line = fmt::format("shown: {} thumbnails against the replayed frames through the "
                                  "display model, ΔE00 p95 {} the tolerance {:.2f}; worst {}",
                                  shown.measured().size(), shown.within() ? "within" : "BEYOND",
                                  shown.tolerance(), worst);
    if (shown.within()) {
        say(line);
        return code;
    }
    logger("replica")->error("{}: {}", o.file, line);
    return kExitFailure;
}

// Keeps the last frame on the display until SIGTERM or SIGINT (--hold).
void holdLastFrame(std::uint64_t frame)
{
    auto log = logger("replica");
    sigset_t stop;
    sigemptyset(&stop);
    sigaddset(&stop, SIGTERM);
    sigaddset(&stop, SIGINT);
    pthread_sigmask(SIG_BLOCK, &stop, nullptr);
    log->info("replay: holding frame {} on the display until SIGTERM or SIGINT", frame);
    int sig = 0;
    sigwait(&stop, &sig);
    log->info("replay: signal {}: released the display", sig);
}

// The summary's keys every replay has.
nlohmann::json baseSummary(const ReplayOptions& o,
                           const LoadedReplay& loaded,
                           const Appliance& appliance,
                           const ReplaySlice& slice,
                           const LoopStats& stats,
                           const FrameOutputs& outputs,
                           double wallS)
{
    nlohmann::json summary{
            {"command", "replay"},
            {"file", o.file},
            {"format_version", loaded.recording.formatVersion},
            {"recorded_by", loaded.recording.session.softwareVersion},
            {"render_profile", loaded.config.renderProfile},
            {"recorded_renderer", loaded.config.drawnByFlatRenderer ? "flat" : "booth"},
            {"clock", o.clock},
            {"renderer", appliance.renderer->description()},
            {"gl_renderer", appliance.output->glRenderer()},
            {"size", {loaded.config.width, loaded.config.height}},
            {"frames_in_recording", loaded.recording.frames.size()},
            {"frames_rendered", stats.frames},
            {"frames_output", outputs.digests().empty() ? slice.frames : outputs.digests().size()},
            {"wall_s", wallS},
            // Session seconds of the frames drawn over the wall seconds they took with their checks
            // (from the first frame to the last check; start-up not counted).
            {"x_real_time",
             wallS > 0.0 ? static_cast<double>(stats.frames) / loaded.config.rateHz / wallS : 0.0},
            {"replay_mismatches", stats.replayMismatches}};
    // The loop's keys as 'run --json' writes them (frame times, drops, gamut); "frames" is
    // frames_rendered.
    summary.update(loopSummaryJson(stats, 1000.0 / loaded.config.rateHz));
    if (o.fromS || o.toS) {
        summary["slice"] = {{"from_s", o.fromS.value_or(0.0)}, {"frames", slice.frames}};
        if (!o.fromWallClock.empty()) {
            summary["slice"]["from"] = o.fromArg;
            summary["slice"]["from_wall_clock"] = o.fromWallClock;
        }
        if (!o.toWallClock.empty()) {
            summary["slice"]["to"] = o.toArg;
            summary["slice"]["to_wall_clock"] = o.toWallClock;
        }
        if (o.toS) {
            summary["slice"]["to_s"] = *o.toS;
        }
    }
    return summary;
}

// The slice's frames drawn on this thread, each checked on the checks' thread (the results in
// 'run'); the loop's figures, and how long the frame thread waited for the checks.
Expected<LoopStats> drawAndCheck(const ReplayOptions& o,
                                 const LoadedReplay& loaded,
                                 Appliance& appliance,
                                 const ReplaySlice& slice,
                                 ReplayRun& run,
                                 pipeline::render::Readback readback,
                                 double& checksWaitedS)
{
    const Pacing pacing = o.clock == "recorded" ? Pacing::Realtime
                          : o.clock == "step"   ? Pacing::Step
                                                : Pacing::Fast;
    Sources sources = makeReplaySources(loaded.recording);
    // The checks overlap the drawing of the next frames; the frames reach them in order.
    FrameWorker worker([&run](const auto& f, const auto& image) { run.check(f, image); });
    auto stats = runFrames(appliance, sources, slice.plan, pacing, nullptr, readback,
                           [&](const auto& f, const auto&, auto& image) {
                               if (run.wanted(f)) {
                                   worker.push(f, image);
                               }
                           });
    worker.finish();
    checksWaitedS = worker.waitedS();
    return stats;
}

// Renders the slice through the checks and reports; the exit code.
int runReplay(const ReplayOptions& o,
              const LoadedReplay& loaded,
              Appliance& appliance,
              const ReplaySlice& slice,
              GoldenCheck& golden,
              std::optional<std::vector<std::uint64_t>> saveOnly,
              bool exact)
{
    auto log = logger("replica");
    // Digests with the golden's own hash, so that format 1 goldens still verify.
    FrameOutputs outputs(!o.digests.empty() || golden.active() || !o.saveFrames.empty(),
                         !o.snapshot.empty(), golden.hash());
    ShownDigests shownDigests;
    for (const auto& d : loaded.recording.displayDigests) {
        if (slice.contains(d.tickNs)) {
            shownDigests.byFrame[d.frameIndex] = d.rgba;
        }
    }
    std::optional<ShownComparison> shown;
    if (!exact || o.compareShown) {
        shown.emplace(loaded.recording, appliance.displayModel, o.shownTolerance);
    }
    auto readback = outputs.readback();
    if (!o.framesOut.empty() || !shownDigests.byFrame.empty() || shown ||
        appliance.output->needsPixels()) {
        readback = std::max(readback, pipeline::render::Readback::Display);
    }
    ReplayRun run{o, slice, outputs, golden, shownDigests, shown, std::move(saveOnly)};
    run.showProgress = !o.noProgress && (o.progress || ::isatty(STDERR_FILENO) == 1);
    if (!o.framesOut.empty() || !o.snapshot.empty()) {
        run.tagPngs(appliance.displayModel, loaded.recording.session.wallClockStartNs);
    }
    // The frames before a slice are only estimated (TickPlan::warmup): they reach no callback.
    run.done = slice.plan.size() - slice.frames;
    double checksWaitedS = 0.0;
    auto stats = drawAndCheck(o, loaded, appliance, slice, run, readback, checksWaitedS);
    const double wallS =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - run.start).count();
    if (run.error) {
        log->error("{}", run.error->message);
        return kExitFailure;
    }
    if (!stats) {
        log->error("{}", stats.error().message);
        return kExitFailure;
    }
    if (auto ok = outputs.finish(o.digests, o.snapshot); !ok) {
        log->error("{}", ok.error().message);
        return kExitFailure;
    }
    const auto say = [&](const std::string& line) {
        if (!o.json) {
            fmt::print("{}\n", line);
        }
    };
    nlohmann::json summary = baseSummary(o, loaded, appliance, slice, *stats, outputs, wallS);
    // The frame thread's wait for the checks' thread: 0 while the checks keep up with the frames.
    summary["checks_waited_s"] = checksWaitedS;
    if (!exact) {
        summary["older_recording"] =
                olderRecordingLine(o.file, loaded.recording.session.softwareVersion,
                                   loaded.config.renderProfile, loaded.config.drawnByFlatRenderer);
    }
    if (loaded.reprocessed) {
        reportReprocess(*loaded.reprocessed, summary, say);
    }
    if (!o.digests.empty()) {
        summary["digests"] = digestsJson(o.digests, golden.hash());
        say(fmt::format("digests: {}", o.digests));
    }
    if (!o.saveFrames.empty()) {
        summary["saved_frames"] = o.saveFrames;
        say(fmt::format("frames: XYZ frames ({}) in {}", o.saveFormat, o.saveFrames));
    }
    if (!o.framesOut.empty()) {
        summary["frames_out"] = {{"dir", o.framesOut}, {"count", run.framesWritten}};
        say(fmt::format("frames out: {} PNG frames in {}", run.framesWritten, o.framesOut));
    }
    reportShownDigests(o, shownDigests, loaded.reprocessed, summary, say);
    int code = stats->replayMismatches > 0 ? kExitLossy : kExitOk;
    code = golden.finish(o, summary, code, say);
    if (shown) {
        code = reportShown(o, *shown, summary, code, say);
    }
    summary["exit_code"] = code;
    if (o.json) {
        fmt::print("{}\n", summary.dump(2));
    }
    if (o.hold && code == kExitOk) {
        // The output stays open (appliance is alive until replayMain returns): the display keeps
        // the last frame until systemd (or the user) stops us.
        holdLastFrame(slice.plan.empty() ? 0 : slice.plan.back().frameIndex);
    }
    return code;
}

} // namespace

int replayMain(const ReplayOptions& given)
{
    auto log = logger("replica");
    ReplayOptions o = given; // --from/--to resolved below
    if (o.output != "headless" && o.output != "kms") {
        log->error("--output {}: expected 'headless' or 'kms'", o.output);
        return kExitUsage;
    }
    auto loadedOr = loadReplay(o);
    if (const int* code = std::get_if<int>(&loadedOr)) {
        return *code;
    }
    LoadedReplay& loaded = std::get<LoadedReplay>(loadedOr);
    const recordings::Recording& recording = loaded.recording;
    RunConfig& config = loaded.config;
    // Wall-clock --from/--to against the recording's start, before anything is built.
    auto sliceLines = resolveSliceTimes(o, recording);
    if (!sliceLines) {
        log->error("{}: {}", o.file, sliceLines.error().message);
        return kExitUsage;
    }
    for (const auto& line : *sliceLines) {
        if (!o.json) {
            fmt::print("{}\n", line);
        }
    }
    // This build draws with the booth pass, today's profile: a recording of another profile or
    // drawn by the flat renderer is bit for bit the build that made it's promise.
    const bool exact =
            pipeline::render::rendersExactly(config.renderProfile) && !config.drawnByFlatRenderer;
    if (!exact && !o.json) {
        fmt::print("{}\n", olderRecordingLine(o.file, recording.session.softwareVersion,
                                              config.renderProfile, config.drawnByFlatRenderer));
    }
    auto appliance = buildReplayAppliance(o, config);
    if (!appliance) {
        log->error("{}", appliance.error().message);
        return kExitFailure;
    }
    // A rotated session file starts where the one before it ended: its estimators' state.
    if (auto ok = restoreStateAtStart(**appliance, recording.session.configJson); !ok) {
        log->error("{}: {}", o.file, ok.error().message);
        return kExitFailure;
    } else if ((*appliance)->sceneEstimator->started()) {
        log->info("{}: a rotated session file: its estimators start from the state it carries",
                  o.file);
    }
    auto slice = makeSlice(o, recording);
    if (!slice) {
        log->error("{}", slice.error().message);
        return kExitUsage;
    }
    std::string counts;
    for (const auto* kind : recordings::deviceKinds()) {
        const auto& noun = kind->names().samplesNoun;
        counts += fmt::format(", {} {}", recording.count(*kind),
                              noun != "samples" ? noun : kind->names().displayName + " samples");
    }
    log->info("replay {}: {} frames{} (recorded by {}); clock={}; renderer={} on {}; {}x{}", o.file,
              recording.frames.size(), counts, recording.session.softwareVersion, o.clock,
              (*appliance)->renderer->description(), (*appliance)->output->glRenderer(),
              config.width, config.height);
    if (o.fromS || o.toS) {
        log->info("slice: {} frames from {} s to {} s ({} frames before it rendered first, not "
                  "output)",
                  slice->frames, o.fromS.value_or(0.0),
                  o.toS ? fmt::format("{}", *o.toS) : std::string("the end"),
                  slice->plan.size() - slice->frames);
    }
    GoldenCheck golden;
    if (auto ok = golden.open(o, *slice, (*appliance)->displayWhiteXyz); !ok) {
        log->error("{}", ok.error().message);
        return kExitFailure;
    }
    if (o.tolerance && !golden.active()) {
        log->error("--tolerance needs --check GOLDEN: it says how far frames may be from the "
                   "golden's reference frames");
        return kExitUsage;
    }
    std::optional<std::vector<std::uint64_t>> saveOnly;
    if (!o.saveOnly.empty()) {
        saveOnly = parseFrameList(o.saveOnly);
        if (!saveOnly) {
            log->error("--save-only {}: expected frame numbers separated by commas, e.g. 0,75,149",
                       o.saveOnly);
            return kExitUsage;
        }
    }
    if (auto ok = makeFrameDirs(o); !ok) {
        log->error("{}", ok.error().message);
        return kExitFailure;
    }
    return runReplay(o, loaded, **appliance, *slice, golden, std::move(saveOnly), exact);
}

} // namespace replica::platform
