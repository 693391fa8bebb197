// The fixed-rate loop: at each tick, poll every source up to the tick time, take the latest sample
// (or, in replay, exactly the sample the recorded frame consumed), update the scene, render, hand
// the frame on, and record what was used.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <pipeline/base/expected.h>
#include <pipeline/render/renderer.h>
#include <platform/appliance.h>
#include <platform/loop/cadence.h>
#include <platform/loop/frame_times.h>
#include <recordings/recording.h>

namespace replica::platform {

enum class Pacing {
    Realtime, // each tick waits for its wall-clock time (the appliance; replay "as recorded")
    Fast,     // as fast as frames render (CI, replay "as fast as possible")
    Step,     // waits for a line on standard input before each frame (frame-stepped replay)
};

// One planned frame. In replay, 'recorded' says which samples the original frame consumed.
struct TickPlan {
    std::uint64_t frameIndex = 0;
    std::int64_t tickNs = 0;
    std::optional<recordings::FrameRecord> recorded;
    // Replay of a slice ('replay --from'): a frame before the slice, run through the state stage
    // only (state/: classifier, held samples, held tilt, encoding), not rendered, so that the
    // slice's first frame has the recording's state. It never waits for its tick or for a step;
    // the first frame after it anchors the pacing.
    bool estimateOnly = false;
};

// Ticks k * period for k = 0 .. frames-1.
std::vector<TickPlan> fixedRatePlan(std::int64_t periodNs, std::uint64_t frames);
// The ticks of a recording, each with the samples it must consume.
std::vector<TickPlan> replayPlan(const std::vector<recordings::FrameRecord>& frames);

struct LoopStats {
    std::uint64_t frames = 0;
    // Device kind name -> samples lost (sequence gaps seen), for every device the run has.
    std::map<std::string, std::uint64_t> dropped;
    // Device kind name -> samples the state stage refused (loop/refusal_log.h): saturated
    // spectra, tilt readings far from 1 g, poses no head can take. Only the kinds that had any.
    std::map<std::string, std::uint64_t> refused;
    std::uint64_t lateFrames = 0; // realtime pacing only: frames that started after their tick
    std::uint64_t replayMismatches = 0; // replay: a recorded sample was not found (latest used)
    std::uint64_t skippedTicks = 0;     // LoopOptions::skipLateTicks: ticks never rendered
    // LoopOptions::maxDivisor: the ticks passed over on purpose for a steady cadence (every n-th
    // tick drawn, loop/cadence.h), how often n changed, the n of the last frame, the frames drawn
    // at each n (index n; 0 unused), and the frames whose work (without the display's flip) took
    // longer than the cadence's period they were drawn at, n periods: the frames that were late
    // for the cadence, where frameTimes counts against the tick period.
    std::uint64_t pacedTicks = 0;
    std::uint64_t framesOverCadence = 0;
    std::uint64_t cadenceChanges = 0;
    int divisor = 1;
    std::array<std::uint64_t, CadenceGovernor::kMaxDivisor + 1> framesAtDivisor{};
    std::uint64_t estimatedOnly = 0; // TickPlan::estimateOnly: ticks only estimated, never drawn
    std::uint64_t recorderRotations = 0; // LoopOptions::nextRecorder returned a new recorder
    // Each frame's work on the wall clock, from polling the sources to handing the frame on
    // (not the wait for its tick): what says whether the machine keeps the rate.
    FrameTimes frameTimes;
    // Over frames: the display pass's per-frame count over the surface's pixels (the whole
    // frame without a surface rectangle; display::GamutCounters::surfaceOutOfGamutFraction), and
    // the share of them above the panel's peak.
    double sumOutOfGamutFraction = 0.0;
    double maxOutOfGamutFraction = 0.0;
    double sumOverPeakFraction = 0.0;
    double maxOverPeakFraction = 0.0;
    double meanOverPeakFraction() const
    {
        return frames > 0 ? sumOverPeakFraction / static_cast<double>(frames) : 0.0;
    }
    double meanOutOfGamutFraction() const
    {
        return frames > 0 ? sumOutOfGamutFraction / static_cast<double>(frames) : 0.0;
    }
};

// The image is the loop's own, drawn again at the next tick: a callback may take its buffers
// (swap xyz and rgba for others, best of the same size, so the next read-back allocates nothing)
// to use them after it returns, as replay's checks on their own thread do (replay_worker.h).
using FrameCallback = std::function<void(const recordings::FrameRecord& frame,
                                         const pipeline::scene::SceneState& state,
                                         pipeline::render::RenderedFrame& image)>;

// Yields the next tick, or nothing when the run is over. Lets the appliance run without end.
using TickSource = std::function<std::optional<TickPlan>()>;

// Ticks k * period for k = 0, 1, 2, ... without end (the kiosk).
TickSource endlessTicks(std::int64_t periodNs);
// Ticks k * period for k = 0 .. frames-1, made one at a time (no plan held in memory).
TickSource fixedRateTicks(std::int64_t periodNs, std::uint64_t frames);
// The most frames 'run --frames' takes: at the slowest rate (1 Hz) their ticks stay far inside
// int64 nanoseconds, and 0 already means "without end".
constexpr std::uint64_t kMaxFrames = 1'000'000'000;

// Whether SIGINT/SIGTERM asked a running loop to stop after the frame in hand, so that recordings
// are closed properly; installStopSignals() routes both signals to an async-signal-safe flag.
bool stopRequested();
void installStopSignals();

// How many ticks to skip so that a frame starting nowNs (since the loop's start) renders a tick
// less than one period old: floor((now - tick) / period) when the frame is at least one period
// late, else 0. The ticks must be periodNs apart (fixedRatePlan, endlessTicks).
std::uint64_t ticksToSkip(std::int64_t nowNs, std::int64_t tickNs, std::int64_t periodNs);

struct LoopOptions {
    // Realtime pacing only: skip (and count) the ticks a slow frame has already missed, so that
    // the display lags its tick by less than one period. For 'replica run' (live pacing); a
    // replay renders every recorded frame and leaves it off.
    bool skipLateTicks = false;
    std::int64_t periodNs = 0;
    // With skipLateTicks: the largest n the loop may draw every n-th tick at when its frames take
    // longer than a period (loop/cadence.h; CadenceGovernor::divisorLimit of the rate and the
    // site's min_rate_hz). 1: every tick, late ones skipped as they come.
    int maxDivisor = 1;
    // After each frame: the systemd watchdog ping and readiness, and the shading passes' warm-up
    // after the first frame (platform/output/pass_warm_up.h); its time is not the frame's.
    std::function<void(const LoopStats&)> afterFrame;
    // After each frame: the recorder for the next frames, 'current' or a new one (rotation). A
    // new one first gets the latest sample of each sensor, so that it replays on its own.
    std::function<recordings::RecordingWriter*(recordings::RecordingWriter* current)> nextRecorder;
};

// Runs the plan. Every polled sample and every frame record go to 'recorder' when it is non-null;
// 'readback' says which images onFrame needs.
Expected<LoopStats> runFrames(Appliance& appliance,
                              Sources& sources,
                              const std::vector<TickPlan>& plan,
                              Pacing pacing,
                              recordings::RecordingWriter* recorder,
                              pipeline::render::Readback readback,
                              const FrameCallback& onFrame);

// The same, ticks drawn one at a time.
Expected<LoopStats> runFrames(Appliance& appliance,
                              Sources& sources,
                              const TickSource& ticks,
                              Pacing pacing,
                              recordings::RecordingWriter* recorder,
                              pipeline::render::Readback readback,
                              const FrameCallback& onFrame,
                              const LoopOptions& options = {});

} // namespace replica::platform
