// The fixed-rate frame loop.
#include <algorithm>
#include <atomic>
#include <chrono>
#include <csignal>
#include <iostream>
#include <map>
#include <string>
#include <thread>
#include <tuple>
#include <type_traits>

#include <state/scene_estimator.h>

#include <hal/log_limiter.h>
#include <platform/logging.h>
#include <platform/loop/frame_loop.h>
#include <platform/loop/refusal_log.h>
#include <recordings/device_kind.h>

namespace replica::platform {
namespace {

volatile std::sig_atomic_t gStop = 0;

extern "C" void onStopSignal(int)
{
    gStop = 1;
}

} // namespace

bool stopRequested()
{
    return gStop != 0;
}

void installStopSignals()
{
    struct sigaction sa {
    };
    sa.sa_handler = onStopSignal;
    sigemptyset(&sa.sa_mask);
    sigaction(SIGINT, &sa, nullptr);
    sigaction(SIGTERM, &sa, nullptr);
    // A file-size limit (ulimit -f) must fail the recording's write (EFBIG, reported like a full
    // disk), not kill the display.
    std::signal(SIGXFSZ, SIG_IGN);
}

TickSource endlessTicks(std::int64_t periodNs)
{
    auto k = std::make_shared<std::uint64_t>(0);
    return [periodNs, k]() -> std::optional<TickPlan> {
        const std::uint64_t i = (*k)++;
        return TickPlan{i, static_cast<std::int64_t>(i) * periodNs, std::nullopt};
    };
}

TickSource fixedRateTicks(std::int64_t periodNs, std::uint64_t frames)
{
    // Made one tick at a time: 'run --frames 10000000' must not hold 10 M plans up front.
    auto k = std::make_shared<std::uint64_t>(0);
    return [periodNs, frames, k]() -> std::optional<TickPlan> {
        if (*k >= frames) {
            return std::nullopt;
        }
        const std::uint64_t i = (*k)++;
        return TickPlan{i, static_cast<std::int64_t>(i) * periodNs, std::nullopt};
    };
}

std::vector<TickPlan> fixedRatePlan(std::int64_t periodNs, std::uint64_t frames)
{
    std::vector<TickPlan> plan;
    plan.reserve(frames);
    for (std::uint64_t k = 0; k < frames; ++k) {
        plan.push_back({k, static_cast<std::int64_t>(k) * periodNs, std::nullopt});
    }
    return plan;
}

std::vector<TickPlan> replayPlan(const std::vector<recordings::FrameRecord>& frames)
{
    std::vector<TickPlan> plan;
    plan.reserve(frames.size());
    for (const auto& f : frames) {
        plan.push_back({f.frameIndex, f.tickNs, f});
    }
    return plan;
}

Expected<LoopStats> runFrames(Appliance& appliance,
                              Sources& sources,
                              const std::vector<TickPlan>& plan,
                              Pacing pacing,
                              recordings::RecordingWriter* recorder,
                              pipeline::render::Readback readback,
                              const FrameCallback& onFrame)
{
    std::size_t next = 0;
    const TickSource ticks = [&plan, &next]() -> std::optional<TickPlan> {
        if (next >= plan.size()) {
            return std::nullopt;
        }
        return plan[next++];
    };
    return runFrames(appliance, sources, ticks, pacing, recorder, readback, onFrame);
}

std::uint64_t ticksToSkip(std::int64_t nowNs, std::int64_t tickNs, std::int64_t periodNs)
{
    if (periodNs <= 0 || nowNs - tickNs < periodNs) {
        return 0;
    }
    return static_cast<std::uint64_t>((nowNs - tickNs) / periodNs);
}

namespace {

// The estimators take exactly one typed sample of each kind of the typed registry, in its order:
// a kind without its consumer (or a consumer without its kind) is a compile error here.
template <typename... Samples>
constexpr bool consumesEachKind(const recordings::KindTuple<Samples...>*)
{
    return std::is_invocable_v<decltype(&state::SceneEstimator::update), state::SceneEstimator&,
                               pipeline::scene::SceneState&, const Samples*...>;
}
static_assert(consumesEachKind(static_cast<const recordings::StateKinds*>(nullptr)),
              "state::SceneEstimator::update must take one sample of each of "
              "recordings::StateKinds, in order");

// "tick", "2nd tick", "3rd tick", "4th tick" ... for the cadence's log lines.
std::string tickOrdinal(int n)
{
    if (n <= 1) {
        return "tick";
    }
    const char* suffix = n == 2 ? "nd" : n == 3 ? "rd" : "th";
    return fmt::format("{}{} tick", n, suffix);
}

// When each frame starts: a realtime tick waits for its wall-clock time (skipping ticks a slow
// frame missed, with skipLateTicks), a stepped one for a line on standard input.
class Pacer
{
public:
    Pacer(Pacing pacing, const LoopOptions& options)
        : pacing_(pacing), options_(options), stepping_(pacing == Pacing::Step),
          wallStart_(std::chrono::steady_clock::now()),
          cadence_(options.periodNs, paced() ? options.maxDivisor : 1)
    {}

    // The next tick to draw, none at the end.
    std::optional<TickPlan> next(const TickSource& ticks, LoopStats& stats)
    {
        std::optional<TickPlan> tick = ticks();
        if (!tick || !paced()) {
            return tick;
        }
        // The plan's last tick is rendered even when passed over or late: a fixed run ends on its
        // last frame.
        const auto advance = [&](std::uint64_t n, std::uint64_t& counter) {
            for (std::uint64_t i = 0; i < n; ++i) {
                std::optional<TickPlan> later = ticks();
                if (!later) {
                    return;
                }
                tick = std::move(later);
                ++counter;
            }
        };
        // A steady cadence: every n-th tick, the n - 1 between passed over (loop/cadence.h).
        const auto n = static_cast<std::uint64_t>(cadence_.divisor());
        advance(n - 1, stats.pacedTicks);
        // Late by a whole cadence period or more: skipped in whole cadence steps, so that the
        // ticks drawn stay n apart.
        const std::uint64_t skip = ticksToSkip(elapsedNs(), tick->tickNs,
                                               options_.periodNs * static_cast<std::int64_t>(n)) *
                                   n;
        advance(skip, stats.skippedTicks);
        if (skip > 0) {
            logger("loop")->debug("late: skipped {} ticks to frame {}", skip, tick->frameIndex);
        }
        return tick;
    }

    // A frame drawn, its work 'workMs' without the display's flip: the cadence's figures, and a
    // new cadence when its frames no longer fit the one in force (or fit a faster one again).
    void drawn(double workMs, LoopStats& stats)
    {
        ++stats.framesAtDivisor[static_cast<std::size_t>(cadence_.divisor())];
        if (paced() && workMs > cadence_.divisor() * cadence_.periodMs()) {
            ++stats.framesOverCadence;
        }
        if (!cadence_.add(workMs)) {
            return;
        }
        const int n = cadence_.divisor();
        const bool slower = n > stats.divisor;
        stats.divisor = n;
        ++stats.cadenceChanges;
        const double period = cadence_.periodMs();
        const double rate = 1000.0 / period;
        if (slower) {
            logger("loop")->info("cadence: frames take {:.1f} ms (the median of the last {}), "
                                 "longer than the {:.1f} ms period: every {} drawn, {:.4g} Hz, "
                                 "so that motion stays even (the lowest allowed: {:.4g} Hz, [run] "
                                 "min_rate_hz)",
                                 cadence_.decidedOnMs(), cadence_.decidedOverFrames(), period,
                                 tickOrdinal(n), rate / n, rate / cadence_.maxDivisor());
        } else {
            logger("loop")->info("cadence: frames fit a faster one again (95th percentile {:.1f} "
                                 "ms of the last {}): every {} drawn, {:.4g} Hz",
                                 cadence_.decidedOnMs(), cadence_.decidedOverFrames(),
                                 tickOrdinal(n), rate / n);
        }
    }

    void wait(const TickPlan& tick, LoopStats& stats)
    {
        if (tick.estimateOnly) {
            afterWarmup_ = true;
        } else if (pacing_ == Pacing::Realtime) {
            if (afterWarmup_) {
                // Pace from here as if the session had started tickNs ago (a slice's first frame).
                wallStart_ = std::chrono::steady_clock::now() -
                             std::chrono::nanoseconds(std::min<std::int64_t>(
                                     tick.tickNs, std::int64_t{1'000'000'000} * 86'400 * 365));
                afterWarmup_ = false;
            }
            // A recording's tick is untrusted (a tick_ns of 9e18 is 285 years away): computed
            // without overflow, and no frame waits more than a second. A live run's ticks are a
            // period apart, at most a second (--rate >= 1), so this never shortens one.
            const std::int64_t elapsed = elapsedNs();
            if (tick.tickNs < elapsed - 2'000'000) {
                ++stats.lateFrames;
            }
            if (tick.tickNs > elapsed) {
                std::this_thread::sleep_for(std::chrono::nanoseconds(
                        std::min<std::int64_t>(tick.tickNs - elapsed, 1'000'000'000)));
            }
        } else if (stepping_) {
            std::string line;
            if (!std::getline(std::cin, line)) {
                stepping_ = false; // input closed: run the rest without waiting
            }
        }
    }

private:
    // Live pacing at a known period: the loop that skips late ticks and may pace a cadence.
    bool paced() const
    {
        return pacing_ == Pacing::Realtime && options_.skipLateTicks && options_.periodNs > 0;
    }

    std::int64_t elapsedNs() const
    {
        return std::chrono::duration_cast<std::chrono::nanoseconds>(
                       std::chrono::steady_clock::now() - wallStart_)
                .count();
    }

    Pacing pacing_;
    const LoopOptions& options_;
    bool stepping_;
    std::chrono::steady_clock::time_point wallStart_;
    bool afterWarmup_ = false;
    CadenceGovernor cadence_;
};

using Slots = decltype(recordings::DeviceSlots(
        recordings::stateKinds(), std::declval<Sources&>(), nullptr));

// Every source polled up to the tick, then each slot's sample for the frame chosen. Lost
// samples are counted in the stats and logged at most once per 10 s per device (wall clock),
// with the count since the last line: a device losing some every frame is one line, not 50 a
// second.
void pollAndChoose(const Slots& slots,
                   const TickPlan& tick,
                   LoopStats& stats,
                   std::map<std::string, hal::LogLimiter>& droppedLog)
{
    const bool replaying = tick.recorded.has_value();
    const std::int64_t wallNs = std::chrono::duration_cast<std::chrono::nanoseconds>(
                                        std::chrono::steady_clock::now().time_since_epoch())
                                        .count();
    for (const auto& slot : slots.all()) {
        const auto& kind = slot->kind();
        const auto d = slot->poll(tick.tickNs);
        stats.dropped[kind.name()] += d;
        auto& limiter = droppedLog[kind.name()];
        if (const auto n = limiter.add(d, wallNs); n > 0) {
            logger("loop")->warn("{} {}: {} {} dropped before t={} ns ({} in all; at most one "
                                 "line per 10 s)",
                                 kind.names().displayName, slot->source().info().serial, n,
                                 kind.names().samplesNoun, tick.tickNs, limiter.total());
        }
    }
    for (const auto& slot : slots.all()) {
        slot->choose(replaying ? tick.recorded->sequence(slot->kind()) : std::nullopt, replaying,
                     stats.replayMismatches);
    }
}

// The display pass's gamut counters of one frame into the run's figures.
void countGamut(const pipeline::render::RenderedFrame& image,
                std::uint64_t frameIndex,
                LoopStats& stats)
{
    // Over the surface's pixels: the black panel around a booth surface is below black by
    // construction and would count whatever the booth and the display do.
    const double oog = image.gamut.surfaceOutOfGamutFraction();
    const auto& g = image.gamut;
    const bool surface = g.surfacePixels > 0;
    logger("loop")->debug("frame {}: {:.4f} of the {} pixels out of gamut (chroma {}, above peak "
                          "{}, below black {})",
                          frameIndex, oog, surface ? "surface's" : "frame's",
                          surface ? g.surfaceChroma : g.chroma,
                          surface ? g.surfaceOverPeak : g.overPeak,
                          surface ? g.surfaceBelowBlack : g.belowBlack);
    stats.sumOutOfGamutFraction += oog;
    stats.maxOutOfGamutFraction = std::max(stats.maxOutOfGamutFraction, oog);
    stats.sumOverPeakFraction += g.surfaceOverPeakFraction();
    stats.maxOverPeakFraction = std::max(stats.maxOverPeakFraction, g.surfaceOverPeakFraction());
}

// After a frame: the recorder for the next ones (a rotation starts its file with the latest
// sample of each device, so that it replays on its own).
recordings::RecordingWriter* nextRecorder(const LoopOptions& options,
                                          recordings::RecordingWriter* recorder,
                                          const Slots& slots,
                                          LoopStats& stats)
{
    if (!options.nextRecorder) {
        return recorder;
    }
    auto* next = options.nextRecorder(recorder);
    if (next != recorder && next != nullptr) {
        for (const auto& slot : slots.all()) {
            slot->writeLatest(*next);
        }
        ++stats.recorderRotations;
    }
    return next;
}

} // namespace

Expected<LoopStats> runFrames(Appliance& appliance,
                              Sources& sources,
                              const TickSource& ticks,
                              Pacing pacing,
                              recordings::RecordingWriter* recorder,
                              pipeline::render::Readback readback,
                              const FrameCallback& onFrame,
                              const LoopOptions& options)
{
    auto log = logger("loop");
    LoopStats stats;
    // One slot per device the run has, in the order they are polled and recorded; each polls its
    // source through the recording decorator (RecordingSource), which writes what it polls to
    // the current recorder ('recorder' changes when the recording rotates). The state stage's
    // kinds are typed: their samples reach the estimators as typed pointers.
    recordings::DeviceSink* tee = recorder;
    const Slots slots(recordings::stateKinds(), sources, &tee);
    for (const auto& slot : slots.all()) {
        stats.dropped[slot->kind().name()] = 0;
    }
    pipeline::scene::SceneState state;
    pipeline::render::RenderedFrame image;
    Pacer pacer(pacing, options);
    std::map<std::string, hal::LogLimiter> droppedLog;
    RefusalLog refusals;
    while (!stopRequested()) {
        const std::optional<TickPlan> next = pacer.next(ticks, stats);
        if (!next) {
            break;
        }
        const TickPlan& tick = *next;
        pacer.wait(tick, stats);
        const auto workStart = std::chrono::steady_clock::now();
        pollAndChoose(slots, tick, stats, droppedLog);
        state.frameIndex = tick.frameIndex;
        state.tickNs = tick.tickNs;
        std::apply(
                [&](const auto*... sample) { appliance.sceneEstimator->update(state, sample...); },
                slots.chosen());
        refusals.after(*appliance.sceneEstimator, tick.tickNs, stats);
        if (tick.estimateOnly) {
            // Before a replayed slice: the state stage alone. A frame is a function of its
            // SceneState (the renderer keeps no history), so nothing before the slice is drawn.
            ++stats.estimatedOnly;
            continue;
        }
        if (auto ok = appliance.renderer->render(state, image, readback); !ok) {
            return tl::unexpected(ok.error());
        }
        countGamut(image, tick.frameIndex, stats);
        DisplayFrame frame{image.width, image.height, image.rgba, image.displayFramebuffer};
        const auto presentStart = std::chrono::steady_clock::now();
        if (auto ok = appliance.output->present(frame); !ok) {
            log->warn("output {}: {}", appliance.output->name(), ok.error().message);
        }
        // A display's present waits for its flip (kms): time the frame did not need, left out
        // of what the cadence decides on.
        const auto presentNs = std::chrono::steady_clock::now() - presentStart;
        recordings::FrameRecord record{tick.frameIndex, tick.tickNs, {}};
        for (const auto& slot : slots.all()) {
            record.setSequence(slot->kind(), slot->chosenSequence());
        }
        if (recorder != nullptr) {
            recorder->write(record);
        }
        if (onFrame) {
            onFrame(record, state, image);
        }
        const double workMs = std::chrono::duration<double, std::milli>(
                                      std::chrono::steady_clock::now() - workStart)
                                      .count();
        stats.frameTimes.add(workMs);
        log->debug("frame {}: {:.1f} ms", tick.frameIndex, workMs);
        ++stats.frames;
        pacer.drawn(workMs - std::chrono::duration<double, std::milli>(presentNs).count(), stats);
        if (options.afterFrame) {
            options.afterFrame(stats);
        }
        recorder = nextRecorder(options, recorder, slots, stats);
        tee = recorder;
    }
    if (stopRequested()) {
        log->info("stop requested: ending after {} frames", stats.frames);
    }
    if (stats.replayMismatches > 0) {
        log->warn("replay: {} recorded samples were missing; the latest sample was used instead",
                  stats.replayMismatches);
    }
    return stats;
}

} // namespace replica::platform
