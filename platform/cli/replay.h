// 'replica replay' in pieces: its options (replay_options.cpp), the slice of frames it outputs
// (replay_slice.cpp), the golden check (replay_check.cpp), what was shown (replay_shown.h) and the
// summary it prints (replay_output.cpp); replay_command.cpp runs them in order.
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include <pipeline/base/expected.h>
#include <pipeline/colour/xyz.h>
#include <platform/cli/frame_compare.h>
#include <platform/loop/frame_digest.h>
#include <platform/loop/frame_loop.h>
#include <platform/output/output.h>
#include <platform/reprocess.h>
#include <recordings/recording.h>

namespace replica::platform {

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
    // --from/--to as given (session seconds, a time of day or ISO 8601: wall_clock_time.h), and
    // the slice they make in seconds of session time (resolveSliceTimes).
    std::string fromArg, toArg;
    std::optional<double> fromS, toS;
    std::string fromWallClock, toWallClock; // the instants a wall-clock --from/--to named
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
    // An older recording's frames against what it showed: the ΔE00 tolerance (replay_shown.h),
    // and whether to compare a recording of this build's render profile too.
    double shownTolerance = 0.0;
    bool compareShown = false;
};

// Runs 'replica replay' with these options; the exit code.
int replayMain(const ReplayOptions& o);

// The frames replay outputs: those whose tick lies in [from, to] (1 us of slack); the frames
// before are rendered (each frame depends on those before it) but neither paced nor output.
struct ReplaySlice {
    std::int64_t fromNs = INT64_MIN;
    std::int64_t untilNs = INT64_MAX;
    std::vector<TickPlan> plan;
    std::size_t frames = 0; // in the slice
    bool contains(std::int64_t tickNs) const { return tickNs >= fromNs && tickNs <= untilNs; }
};
// --from/--to (o.fromArg, o.toArg) as seconds of session time into o.fromS, o.toS: session seconds
// as given, wall-clock times against the recording's start; the lines saying where each wall-clock
// time landed ("--from 14:32:05 is session second 1925.5 (...)"), or a usage error (exit 2).
Expected<std::vector<std::string>> resolveSliceTimes(ReplayOptions& o,
                                                     const recordings::Recording& recording);
// The slice of 'recording' the options ask for; a usage error (the message, exit 2) when it is
// empty or backwards.
Expected<ReplaySlice> makeSlice(const ReplayOptions& o, const recordings::Recording& recording);

// "0,75,149" -> {0, 75, 149}; nullopt on anything else.
std::optional<std::vector<std::uint64_t>> parseFrameList(const std::string& s);

// ΔE00 of one frame against its reference, with where the largest difference is (x, y from the
// top-left of the picture).
struct FrameDeltaE {
    long frame = -1;
    DeltaEStats stats;
    int maxX = 0, maxY = 0;
    std::filesystem::path reference;
};

std::filesystem::path
framePath(const std::filesystem::path& dir, long frame, const char* suffix = ".pfm");

// --check GOLDEN: each replayed frame's digest against the golden's, the differing frames measured
// against their reference frames.
class GoldenCheck
{
public:
    // Reads the golden (its frames inside the slice); fails with the message.
    Expected<void>
    open(const ReplayOptions& o, const ReplaySlice& slice, pipeline::colour::Xyz white);
    bool active() const { return golden_.has_value(); }
    DigestHash hash() const { return golden_ ? golden_->hash : kDigestHash; }
    // One replayed frame of the slice and its digest.
    Expected<void>
    frame(long frameNo, const pipeline::render::RenderedFrame& image, const FrameDigest& digest);
    // The check's result into summary["check"], its lines through 'say' (errors to the log);
    // the exit code it makes ('code' when it passes).
    int finish(const ReplayOptions& o,
               nlohmann::json& summary,
               int code,
               const std::function<void(const std::string&)>& say) const;

private:
    Expected<void> measure(long frameNo, const pipeline::render::RenderedFrame& image);
    void reportBeyond(const ReplayOptions& o,
                      nlohmann::json& check,
                      const std::function<void(const std::string&)>& say) const;

    std::optional<DigestFile> golden_;
    std::map<std::uint64_t, FrameDigest> byFrame_; // the golden frames inside the slice
    std::filesystem::path refDir_;
    pipeline::colour::Xyz white_{0.0};
    std::optional<FloatImage> firstDiffXyz_;
    std::vector<std::uint8_t> firstDiffRgba_;
    long firstDiff_ = -1;
    std::uint64_t differing_ = 0, compared_ = 0, seen_ = 0;
    std::vector<FrameDeltaE> measured_; // differing frames with a reference frame
};

// The recording's own digests of what the panel showed (format 4), by frame, inside the slice.
struct ShownDigests {
    std::map<std::uint64_t, std::uint64_t> byFrame;
    std::uint64_t matched = 0, differing = 0;
    long firstDiffering = -1;
    // 'rgbaXxh3': the frame's XXH3-64 when the caller has it already (the digests'), else
    // hashed here.
    void frame(std::uint64_t frameIndex,
               const std::vector<std::uint8_t>& rgba,
               std::optional<std::uint64_t> rgbaXxh3 = std::nullopt);
};

// What replay prints at the end, besides the checks: the reprocessing report and the display
// digests' verdict, into 'summary' and through 'say'.
void reportReprocess(const ReprocessReport& r,
                     nlohmann::json& summary,
                     const std::function<void(const std::string&)>& say);
void reportShownDigests(const ReplayOptions& o,
                        const ShownDigests& shown,
                        const std::optional<ReprocessReport>& reprocessed,
                        nlohmann::json& summary,
                        const std::function<void(const std::string&)>& say);

} // namespace replica::platform
