// 'replica replay': feeds a recording back through the replay HAL and renders the same frames.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <map>
#include <optional>
#include <sstream>
#include <vector>

#include <fmt/format.h>
#include <nlohmann/json.hpp>
#include <pthread.h>
#include <unistd.h>

#include <platform/appliance.h>
#include <platform/cli/commands.h>
#include <platform/cli/frame_compare.h>
#include <platform/cli/frame_outputs.h>
#include <platform/cli/loop_summary.h>
#include <platform/image/png_writer.h>
#include <platform/image/xyz_frame.h>
#include <platform/logging.h>
#include <platform/loop/frame_loop.h>
#include <platform/reprocess.h>

namespace replica::platform {
namespace {

struct ReplayOptions {
    std::string file;
    std::string digests;
    std::string check;
    std::string snapshot;
    std::string clock = "fast";
    std::string saveFrames;  // write every frame's XYZ here (reference frames for a golden)
    std::string reference;   // reference XYZ frames for --check (default: GOLDEN.frames/)
    std::string mismatchDir; // where --check writes the first differing frame
    std::vector<std::string> dataRoots; // folders besides data/ a recording may name files in
    bool allowUndigested = false;       // replay a recording without scene/display digests
    std::optional<double> fromS, toS;   // the slice, in seconds of session time
    std::string framesOut; // PNG of every displayed frame of the slice (--frames-out, --save-png)
    bool json = false;
    bool progress = false; // progress lines even when standard error is not a terminal
    bool noProgress = false;
    std::optional<double> tolerance; // --check passes within this ΔE00 on the reference frames
    std::string saveOnly;            // with --save-frames: only these frame numbers
    std::string saveFormat = "pfm";  // or "exr" (half float)
    std::string output = "headless";
    bool reprocess = false; // re-derive samples from their recorded raw inputs
    std::optional<std::string> trackerAxes, accelAxes; // with --reprocess: instead of recorded
    KmsOptions kms;
    bool hold = false; // keep the last frame on the display until SIGTERM/SIGINT
    bool noWarmUp = false;
};

// The reference frame of `frame` in dir: .exr (committed goldens) or .pfm (local).
std::optional<std::filesystem::path> referenceFrame(const std::filesystem::path& dir, long frame)
{
    std::error_code ec;
    for (const char* ext : {".exr", ".pfm"}) {
        auto p = dir / fmt::format("frame-{:06d}{}", frame, ext);
        if (std::filesystem::exists(p, ec)) {
            return p;
        }
    }
    return std::nullopt;
}

// "0,75,149" -> {0, 75, 149}; nullopt on anything else.
std::optional<std::vector<std::uint64_t>> parseFrameList(const std::string& s)
{
    std::vector<std::uint64_t> out;
    std::stringstream in(s);
    std::string item;
    while (std::getline(in, item, ',')) {
        std::size_t used = 0;
        try {
            out.push_back(std::stoull(item, &used));
        } catch (const std::exception&) {
            return std::nullopt;
        }
        if (used != item.size()) {
            return std::nullopt;
        }
    }
    if (out.empty()) {
        return std::nullopt;
    }
    return out;
}

// ΔE00 of one frame against its reference, with where the largest difference is (x, y from the
// top-left of the picture).
struct FrameDeltaE {
    long frame = -1;
    DeltaEStats stats;
    int maxX = 0, maxY = 0;
    std::filesystem::path reference;
};

// One measured frame as --json reports it (the worst adds its reference file).
nlohmann::json frameDeltaEJson(const FrameDeltaE& m)
{
    return {{"frame", m.frame},
            {"mean", m.stats.mean},
            {"p95", m.stats.p95},
            {"max", m.stats.max},
            {"max_at", {m.maxX, m.maxY}}};
}

std::filesystem::path
framePath(const std::filesystem::path& dir, long frame, const char* suffix = ".pfm")
{
    return dir / fmt::format("frame-{:06d}{}", frame, suffix);
}

// Writes the first differing frame, and, when its reference frame exists, the ΔE00 difference
// image and statistics. Returns the report lines.
Expected<void> reportMismatch(const ReplayOptions& o,
                              long frame,
                              const FloatImage& xyz,
                              const std::vector<std::uint8_t>& rgba,
                              const pipeline::colour::Xyz& white)
{
    std::filesystem::path dir = o.mismatchDir;
    if (dir.empty()) {
        dir = o.digests.empty() ? std::filesystem::path("replay-mismatch")
                                : std::filesystem::path(o.digests).replace_extension(".mismatch");
    }
    std::error_code ec;
    std::filesystem::create_directories(dir, ec);
    if (ec) {
        return makeError(ErrorCode::Io, fmt::format("{}: cannot create directory: {}", dir.string(),
                                                    ec.message()));
    }
    if (auto ok = writePng(framePath(dir, frame, ".png"), xyz.width, xyz.height, rgba); !ok) {
        return ok;
    }
    if (auto ok = writePfm(framePath(dir, frame), xyz); !ok) {
        return ok;
    }
    fmt::print("first differing frame {}: replayed frame written to {} (XYZ {})\n", frame,
               framePath(dir, frame, ".png").string(), framePath(dir, frame).string());
    std::filesystem::path refDir = o.reference;
    if (refDir.empty()) {
        refDir = std::filesystem::path(o.check).replace_extension(".frames");
    }
    const auto found = referenceFrame(refDir, frame);
    if (!found) {
        fmt::print("no reference frame {} (write reference frames with 'replica replay FILE "
                   "--save-frames DIR' and pass --reference DIR): no ΔE00 statistics\n",
                   framePath(refDir, frame).string());
        return {};
    }
    const auto refPath = *found;
    auto ref = readXyzFrame(refPath);
    if (!ref) {
        return tl::unexpected(ref.error());
    }
    auto de = deltaE00Image(xyz, *ref, white);
    if (!de) {
        return makeError(ErrorCode::InvalidArgument,
                         fmt::format("{}: {}", refPath.string(), de.error().message));
    }
    const auto diffPath = framePath(dir, frame, "-diff.png");
    if (auto ok = writeDifferencePng(diffPath, xyz.width, xyz.height, *de); !ok) {
        return ok;
    }
    const auto st = summarise(*de);
    fmt::print("ΔE00 against {} over {} pixels: mean {:.3f}, median {:.3f}, p95 {:.3f}, max "
               "{:.3f}; {:.2f}% above 1, {:.2f}% above 2; difference image {}\n",
               refPath.string(), st.pixels, st.mean, st.median, st.p95, st.max,
               100.0 * st.fractionAbove1, 100.0 * st.fractionAbove2, diffPath.string());
    return {};
}

int replayMain(const ReplayOptions& o)
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
    std::optional<ReprocessReport> reprocessed;
    if ((o.trackerAxes || o.accelAxes) && !o.reprocess) {
        log->error("--tracker-axes and --accel-axes change how raw inputs are processed: they "
                   "need --reprocess");
        return kExitUsage;
    }
    if (o.reprocess) {
        ReprocessOptions ro;
        ro.trackerAxes = o.trackerAxes;
        ro.accelAxes = o.accelAxes;
        auto r = reprocess(*recording, ro);
        if (!r) {
            log->error("{}: --reprocess: {}", o.file, r.error().message);
            return kExitFailure;
        }
        reprocessed = *r;
        if (r->posesNonFinite + r->accelNonFinite > 0) {
            log->warn("{}: --reprocess: {} poses and {} accelerometer samples came out not finite "
                      "(a recorded scale or raw value out of range); the loop ignores them as it "
                      "does a device's NaN",
                      o.file, r->posesNonFinite, r->accelNonFinite);
        }
        if (r->posesReprocessed + r->accelReprocessed == 0) {
            log->warn("{}: --reprocess: the recording holds no raw inputs of the tracker or "
                      "accelerometer (format {}; they are recorded from format 5 on, from live "
                      "devices and the simulated accelerometer): replaying their recorded "
                      "samples",
                      o.file, recording->formatVersion);
        }
    }
    for (std::size_t i = 0; i < recording->frames.size(); ++i) {
        const std::int64_t before = i > 0 ? recording->frames[i - 1].tickNs : 0;
        if (recording->frames[i].tickNs < before) {
            log->error("{}: frame {} has tick_ns {}, before {} (the session start or the frame "
                       "ahead of it): the frame channel is corrupt",
                       o.file, recording->frames[i].frameIndex, recording->frames[i].tickNs,
                       before);
            return kExitFailure;
        }
    }
    if (o.output != "headless" && o.output != "kms") {
        log->error("--output {}: expected 'headless' or 'kms'", o.output);
        return kExitUsage;
    }
    OutputChoice outputChoice;
    outputChoice.kind = o.output;
    outputChoice.kms = o.kms;
    if (o.output == "kms" && o.kms.mode.empty()) {
        // The recording's frame size is the mode to ask for; the preferred one if there is none
        // of that size (the frame is then centred or cropped).
        outputChoice.kms.mode = fmt::format("{}x{}", config->width, config->height);
        outputChoice.kms.modeOrPreferred = true;
    }
    config->warmUp = !o.noWarmUp; // not recorded: the frames are the same either way
    auto appliance = buildAppliance(*config, outputChoice);
    if (!appliance) {
        log->error("{}", appliance.error().message);
        return kExitFailure;
    }
    // A rotated session file starts where the one before it ended: its estimators' state.
    if (auto ok = restoreStateAtStart(**appliance, recording->session.configJson); !ok) {
        log->error("{}: {}", o.file, ok.error().message);
        return kExitFailure;
    } else if ((*appliance)->updater->started()) {
        log->info("{}: a rotated session file: its estimators start from the state it carries",
                  o.file);
    }
    Sources sources = makeReplaySources(*recording);
    const Pacing pacing = o.clock == "recorded" ? Pacing::Realtime
                          : o.clock == "step"   ? Pacing::Step
                                                : Pacing::Fast;
    // The slice: frames whose tick lies in [from, to]. Frames before it are rendered (the state
    // carried from frame to frame must be the recording's) but neither paced nor output.
    const auto toNs = [](double sec) { return static_cast<std::int64_t>(std::llround(sec * 1e9)); };
    // 1 us of slack: tick k is k * round(period), a few ns off k / rate after many frames.
    constexpr std::int64_t kSlackNs = 1000;
    const std::int64_t fromNs = o.fromS ? toNs(*o.fromS) - kSlackNs : INT64_MIN;
    const std::int64_t untilNs = o.toS ? toNs(*o.toS) + kSlackNs : INT64_MAX;
    if (fromNs > untilNs) {
        log->error("--from {} is after --to {}: nothing to replay", *o.fromS, *o.toS);
        return kExitUsage;
    }
    auto inSlice = [&](std::int64_t tickNs) { return tickNs >= fromNs && tickNs <= untilNs; };
    std::vector<TickPlan> plan;
    std::size_t sliceFrames = 0;
    for (const auto& f : recording->frames) {
        if (f.tickNs > untilNs) {
            break;
        }
        TickPlan t{f.frameIndex, f.tickNs, f};
        t.warmup = !inSlice(f.tickNs);
        sliceFrames += t.warmup ? 0 : 1;
        plan.push_back(t);
    }
    if ((o.fromS || o.toS) && sliceFrames == 0) {
        const double lastS = recording->frames.empty()
                                     ? 0.0
                                     : static_cast<double>(recording->frames.back().tickNs) * 1e-9;
        log->error("{}: no frame between {} s and {} s (the recording's frames span 0 to {:.3f} "
                   "s of session time)",
                   o.file, o.fromS.value_or(0.0), o.toS ? fmt::format("{}", *o.toS) : "the end",
                   lastS);
        return kExitUsage;
    }
    std::string counts;
    for (const auto* kind : recordings::deviceKinds()) {
        const auto& noun = kind->names().samplesNoun;
        counts += fmt::format(", {} {}", recording->count(*kind),
                              noun != "samples" ? noun : kind->names().displayName + " samples");
    }
    log->info("replay {}: {} frames{} (recorded by {}); clock={}; renderer={} on {}; {}x{}", o.file,
              recording->frames.size(), counts, recording->session.softwareVersion, o.clock,
              (*appliance)->renderer->description(), (*appliance)->output->glRenderer(),
              config->width, config->height);
    if (o.fromS || o.toS) {
        log->info("slice: {} frames from {} s to {} s ({} frames before it rendered first, not "
                  "output)",
                  sliceFrames, o.fromS.value_or(0.0),
                  o.toS ? fmt::format("{}", *o.toS) : std::string("the end"),
                  plan.size() - sliceFrames);
    }

    std::optional<DigestFile> golden;
    std::map<std::uint64_t, FrameDigest> goldenByFrame; // the golden frames inside the slice
    if (!o.check.empty()) {
        auto g = readDigestFile(o.check);
        if (!g) {
            log->error("{}", g.error().message);
            return kExitFailure;
        }
        for (const auto& d : g->frames) {
            if (inSlice(d.tickNs) && d.tickNs <= untilNs) {
                goldenByFrame[d.frameIndex] = d;
            }
        }
        golden = std::move(*g);
    }
    if (o.tolerance && !golden) {
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
    for (const auto* dir : {&o.saveFrames, &o.framesOut}) {
        if (dir->empty()) {
            continue;
        }
        std::error_code ec;
        std::filesystem::create_directories(*dir, ec);
        if (ec) {
            log->error("{}: cannot create directory: {}", *dir, ec.message());
            return kExitFailure;
        }
    }
    // Digests with the golden's own hash, so that format 1 goldens still verify.
    const DigestHash hash = golden ? golden->hash : kDigestHash;
    FrameOutputs outputs(!o.digests.empty() || golden || !o.saveFrames.empty(), !o.snapshot.empty(),
                         hash);
    // The recording's own digests of what the panel showed (format 4), by frame.
    std::map<std::uint64_t, std::uint64_t> shown;
    for (const auto& d : recording->displayDigests) {
        if (inSlice(d.tickNs)) {
            shown[d.frameIndex] = d.rgba;
        }
    }
    auto readback = outputs.readback();
    if (!o.framesOut.empty() || !shown.empty()) {
        readback = std::max(readback, pipeline::render::Readback::Display);
    }
    std::filesystem::path refDir = o.reference;
    if (refDir.empty() && golden) {
        refDir = std::filesystem::path(o.check).replace_extension(".frames");
    }
    const pipeline::colour::Xyz white = (*appliance)->displayWhiteXyz;

    // Keep the first frame whose digest differs from the golden one, and save frames on request.
    std::optional<FloatImage> firstDiffXyz;
    std::vector<std::uint8_t> firstDiffRgba;
    long firstDiff = -1;
    std::uint64_t differing = 0, compared = 0, goldenSeen = 0;
    std::vector<FrameDeltaE> measured; // tolerance mode: differing frames with a reference
    std::uint64_t shownMatched = 0, shownDiffering = 0;
    long firstShownDiff = -1;
    std::optional<Error> saveError;
    std::uint64_t framesWritten = 0;
    auto keep = outputs.callback();
    const bool showProgress = !o.noProgress && (o.progress || ::isatty(STDERR_FILENO) == 1);
    const auto wallStart = std::chrono::steady_clock::now();
    auto lastProgress = wallStart;
    // The frames before a slice are only estimated (TickPlan::warmup): they reach no callback.
    std::uint64_t done = plan.size() - sliceFrames;
    auto onFrame = [&](const recordings::FrameRecord& f, const pipeline::scene::SceneState& scene,
                       const pipeline::render::RenderedFrame& image) {
        ++done;
        if (showProgress) {
            const auto now = std::chrono::steady_clock::now();
            if (now - lastProgress >= std::chrono::seconds(1) || done == plan.size()) {
                lastProgress = now;
                const double el = std::chrono::duration<double>(now - wallStart).count();
                const double rate = el > 0.0 ? static_cast<double>(done) / el : 0.0;
                const double left =
                        rate > 0.0 ? static_cast<double>(plan.size() - done) / rate : 0.0;
                std::fprintf(stderr,
                             "replay: frame %llu (%llu of %zu, %.0f%%), session time %.1f s, "
                             "%.1f frames/s, %.0f s left%s\n",
                             static_cast<unsigned long long>(f.frameIndex),
                             static_cast<unsigned long long>(done), plan.size(),
                             100.0 * static_cast<double>(done) /
                                     static_cast<double>(std::max<std::size_t>(plan.size(), 1)),
                             static_cast<double>(f.tickNs) * 1e-9, rate, left,
                             inSlice(f.tickNs) ? "" : " (before the slice)");
            }
        }
        if (!inSlice(f.tickNs)) {
            return;
        }
        keep(f, scene, image);
        if (auto it = shown.find(f.frameIndex); it != shown.end() && !image.rgba.empty()) {
            if (xxh3_64(image.rgba) == it->second) {
                ++shownMatched;
            } else {
                ++shownDiffering;
                if (firstShownDiff < 0) {
                    firstShownDiff = static_cast<long>(f.frameIndex);
                }
            }
        }
        const auto frameNo = static_cast<long>(f.frameIndex);
        if (!o.framesOut.empty() && !saveError) {
            if (auto ok = writePng(framePath(o.framesOut, frameNo, ".png"), image.width,
                                   image.height, image.rgba);
                !ok) {
                saveError = ok.error();
            } else {
                ++framesWritten;
            }
        }
        const bool save =
                !o.saveFrames.empty() && (!saveOnly || std::find(saveOnly->begin(), saveOnly->end(),
                                                                 f.frameIndex) != saveOnly->end());
        if (save && !saveError) {
            if (auto ok = writeXyzFrame(
                        framePath(o.saveFrames, frameNo, o.saveFormat == "exr" ? ".exr" : ".pfm"),
                        {image.width, image.height, image.xyz});
                !ok) {
                saveError = ok.error();
            }
        }
        if (!golden) {
            return;
        }
        ++compared;
        const auto g = goldenByFrame.find(f.frameIndex);
        goldenSeen += g != goldenByFrame.end() ? 1 : 0;
        if (g != goldenByFrame.end() && g->second == outputs.digests().back()) {
            return;
        }
        ++differing;
        if (!firstDiffXyz) {
            firstDiff = frameNo;
            firstDiffXyz = FloatImage{image.width, image.height, image.xyz};
            firstDiffRgba = image.rgba;
        }
        // Measure every differing frame that has a reference frame: tolerance mode decides on
        // them, and a plain --check reports them.
        {
            if (const auto ref = referenceFrame(refDir, frameNo)) {
                auto r = readXyzFrame(*ref);
                if (!r) {
                    saveError = r.error();
                    return;
                }
                auto de = deltaE00Image({image.width, image.height, image.xyz}, *r, white);
                if (!de) {
                    saveError = Error{ErrorCode::InvalidArgument,
                                      fmt::format("{}: {}", ref->string(), de.error().message)};
                    return;
                }
                FrameDeltaE m;
                m.frame = frameNo;
                m.reference = *ref;
                const auto at = static_cast<std::size_t>(std::max_element(de->begin(), de->end()) -
                                                         de->begin());
                m.maxX = static_cast<int>(at % static_cast<std::size_t>(image.width));
                m.maxY = image.height - 1 -
                         static_cast<int>(at / static_cast<std::size_t>(image.width));
                m.stats = summarise(std::move(*de));
                measured.push_back(m);
            }
        }
    };
    if ((*appliance)->output->needsPixels() && readback == pipeline::render::Readback::None) {
        readback = pipeline::render::Readback::Display;
    }
    auto stats = runFrames(**appliance, sources, plan, pacing, nullptr, readback, onFrame);
    const double wallS =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - wallStart).count();
    if (saveError) {
        log->error("{}", saveError->message);
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
    auto say = [&](const std::string& line) {
        if (!o.json) {
            fmt::print("{}\n", line);
        }
    };
    nlohmann::json summary{
            {"command", "replay"},
            {"file", o.file},
            {"format_version", recording->formatVersion},
            {"recorded_by", recording->session.softwareVersion},
            {"clock", o.clock},
            {"renderer", (*appliance)->renderer->description()},
            {"gl_renderer", (*appliance)->output->glRenderer()},
            {"size", {config->width, config->height}},
            {"frames_in_recording", recording->frames.size()},
            {"frames_rendered", stats->frames},
            {"frames_output", outputs.digests().empty() ? sliceFrames : outputs.digests().size()},
            {"wall_s", wallS},
            {"replay_mismatches", stats->replayMismatches}};
    // The loop's keys as 'run --json' writes them (frame times, drops, gamut); "frames" is
    // frames_rendered.
    summary.update(loopSummaryJson(*stats, 1000.0 / config->rateHz));
    if (o.fromS || o.toS) {
        summary["slice"] = {{"from_s", o.fromS.value_or(0.0)}, {"frames", sliceFrames}};
        if (o.toS) {
            summary["slice"]["to_s"] = *o.toS;
        }
    }
    if (reprocessed) {
        const ReprocessReport& r = *reprocessed;
        summary["reprocess"] = {{"poses", r.poses},
                                {"poses_reprocessed", r.posesReprocessed},
                                {"poses_changed", r.posesChanged},
                                {"pose_times_differ", r.poseTimesDiffer},
                                {"accel", r.accel},
                                {"accel_reprocessed", r.accelReprocessed},
                                {"accel_changed", r.accelChanged},
                                {"lamp", r.lamp},
                                {"lamp_reprocessed", r.lampReprocessed},
                                {"lamp_changed", r.lampChanged},
                                {"poses_non_finite", r.posesNonFinite},
                                {"accel_non_finite", r.accelNonFinite}};
        say(fmt::format("reprocessed: {} of {} poses ({} changed) and {} of {} accelerometer "
                        "samples ({} changed) from their raw inputs; the rest as recorded",
                        r.posesReprocessed, r.poses, r.posesChanged, r.accelReprocessed, r.accel,
                        r.accelChanged));
        if (r.lamp > 0) {
            say(fmt::format("reprocessed: {} of {} lamp selector positions decoded again from "
                            "their line levels ({} changed)",
                            r.lampReprocessed, r.lamp, r.lampChanged));
        }
        if (r.poseTimesDiffer > 0) {
            say(fmt::format("reprocessed: {} HID reports' device times map to other session "
                            "times than recorded; the samples keep their recorded times",
                            r.poseTimesDiffer));
        }
    }
    if (!o.digests.empty()) {
        summary["digests"] = digestsJson(o.digests, hash);
        say(fmt::format("digests: {}", o.digests));
    }
    if (!o.saveFrames.empty()) {
        summary["saved_frames"] = o.saveFrames;
        say(fmt::format("frames: XYZ frames ({}) in {}", o.saveFormat, o.saveFrames));
    }
    if (!o.framesOut.empty()) {
        summary["frames_out"] = {{"dir", o.framesOut}, {"count", framesWritten}};
        say(fmt::format("frames out: {} PNG frames in {}", framesWritten, o.framesOut));
    }
    if (!shown.empty()) {
        summary["display_digests"] = {{"recorded", shown.size()},
                                      {"matched", shownMatched},
                                      {"differing", shownDiffering}};
        if (shownDiffering > 0) {
            summary["display_digests"]["first_differing_frame"] = firstShownDiff;
            const bool reprocessedChanges =
                    reprocessed && reprocessed->posesChanged + reprocessed->accelChanged +
                                                   reprocessed->lampChanged >
                                           0;
            log->warn("{}: {} of {} frames differ from the digests of what the panel showed "
                      "when recorded (first: frame {}); {}",
                      o.file, shownDiffering, shownMatched + shownDiffering, firstShownDiff,
                      reprocessedChanges
                              ? "--reprocess changed samples, as expected"
                              : "this machine renders differently (a different Mesa or GPU?)");
        } else {
            say(fmt::format("shown: all {} frames match the recorded digests of what the panel "
                            "showed",
                            shownMatched));
        }
    }
    int code = stats->replayMismatches > 0 ? kExitLossy : kExitOk;
    if (golden) {
        // Golden frames in the slice that were not replayed make the check fail too.
        const std::uint64_t missing = goldenByFrame.size() - goldenSeen;
        const bool lengthDiffers = missing > 0;
        nlohmann::json check{{"golden", o.check},
                             {"hash", digestHashName(hash)},
                             {"frames_compared", compared},
                             {"golden_frames", goldenByFrame.size()},
                             {"frames_differing", differing},
                             {"golden_frames_not_replayed", missing}};
        if (differing == 0 && !lengthDiffers) {
            check["result"] = "match";
            say(fmt::format("check: all {} frames match {}", compared, o.check));
        } else if (o.tolerance && !lengthDiffers && !measured.empty()) {
            const auto worst = *std::max_element(
                    measured.begin(), measured.end(),
                    [](const auto& a, const auto& b) { return a.stats.max < b.stats.max; });
            const bool within = worst.stats.max <= *o.tolerance;
            check["result"] = within ? "within_tolerance" : "beyond_tolerance";
            check["tolerance_de00"] = *o.tolerance;
            check["reference_frames_measured"] = measured.size();
            check["worst"] = frameDeltaEJson(worst);
            check["worst"]["reference"] = worst.reference.string();
            nlohmann::json frames = nlohmann::json::array();
            for (const auto& m : measured) {
                frames.push_back(frameDeltaEJson(m));
            }
            check["measured"] = frames;
            const auto line = fmt::format(
                    "check: {} of {} frames differ from {} bit for bit; on the {} of them with "
                    "reference frames ΔE00 is at most {:.3f} (worst frame {}: mean {:.3f}, p95 "
                    "{:.3f}, max {:.3f} at x {} y {}), {} the tolerance {:.3f} by {:.3f}",
                    differing, compared, o.check, measured.size(), worst.stats.max, worst.frame,
                    worst.stats.mean, worst.stats.p95, worst.stats.max, worst.maxX, worst.maxY,
                    within ? "within" : "BEYOND", *o.tolerance,
                    std::abs(*o.tolerance - worst.stats.max));
            if (within) {
                say(line);
            } else {
                log->error("{}", line);
                code = kExitFailure;
            }
        } else {
            check["result"] = "differ";
            check["first_differing_frame"] = firstDiff;
            log->error("{}: frame {} differs from the golden digests in {} ({} golden frames, {} "
                       "replayed{})",
                       o.file, firstDiff, o.check, goldenByFrame.size(), compared,
                       o.tolerance ? "; no reference frame among the differing frames, so no "
                                     "tolerance applies"
                                   : "");
            if (firstDiffXyz && !o.json) {
                if (auto ok = reportMismatch(o, firstDiff, *firstDiffXyz, firstDiffRgba, white);
                    !ok) {
                    log->error("{}", ok.error().message);
                }
            }
            nlohmann::json frames = nlohmann::json::array();
            for (const auto& m : measured) {
                frames.push_back(frameDeltaEJson(m));
                say(fmt::format("reference frame {}: ΔE00 mean {:.3f}, p95 {:.3f}, max {:.3f} at "
                                "x {} y {} ({})",
                                m.frame, m.stats.mean, m.stats.p95, m.stats.max, m.maxX, m.maxY,
                                m.reference.string()));
            }
            check["measured"] = frames;
            code = kExitFailure;
        }
        summary["check"] = check;
    }
    summary["exit_code"] = code;
    if (o.json) {
        fmt::print("{}\n", summary.dump(2));
    }
    if (o.hold && code == kExitOk) {
        // The output stays open (appliance is alive until we return): the display keeps the
        // last frame until systemd (or the user) stops us.
        sigset_t stop;
        sigemptyset(&stop);
        sigaddset(&stop, SIGTERM);
        sigaddset(&stop, SIGINT);
        pthread_sigmask(SIG_BLOCK, &stop, nullptr);
        log->info("replay: holding frame {} on the display until SIGTERM or SIGINT",
                  plan.empty() ? 0 : plan.back().frameIndex);
        int sig = 0;
        sigwait(&stop, &sig);
        log->info("replay: signal {}: released the display", sig);
    }
    return code;
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
    cmd->add_option("--reference", opts->reference,
                    "reference XYZ frames for --check (default: GOLDEN with .frames instead of "
                    ".json, if it exists): on a mismatch, ΔE00 of the first differing frame");
    cmd->add_option("--mismatch-dir", opts->mismatchDir,
                    "where --check writes the first differing frame and the difference image "
                    "(default: OUT.mismatch beside --digests OUT, else ./replay-mismatch)");
    cmd->add_option("--from", opts->fromS,
                    "replay only the frames from T seconds of session time on (the frames before "
                    "are rendered first, fast, since each frame depends on those before it)")
            ->check(CLI::Range(0.0, 1e9));
    cmd->add_option("--to", opts->toS, "... up to T seconds of session time (inclusive)")
            ->check(CLI::Range(0.0, 1e9));
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
    cmd->add_option("--tolerance", opts->tolerance,
                    "with --check: pass when frames that differ from the golden bit for bit are "
                    "within DE00 (largest CIEDE2000 of any pixel) of the golden's reference "
                    "frames (GOLDEN.frames/ or --reference); say by how much")
            ->check(CLI::Range(0.0, 100.0));
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
    cmd->callback([opts, &exitCode] { exitCode = replayMain(*opts); });
}

} // namespace replica::platform
