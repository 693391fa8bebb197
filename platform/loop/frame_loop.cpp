// The fixed-rate frame loop.
#include <algorithm>
#include <atomic>
#include <chrono>
#include <csignal>
#include <iostream>
#include <string>
#include <thread>

#include <platform/logging.h>
#include <platform/loop/frame_loop.h>
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
    // the current recorder ('recorder' changes when the recording rotates).
    recordings::DeviceSink* tee = recorder;
    std::vector<std::unique_ptr<recordings::DeviceSlot>> slots;
    for (auto& e : sources.entries()) {
        if (e.source) {
            slots.push_back(e.kind->makeSlot(*e.source, &tee));
            stats.dropped[e.kind->name()] = 0;
        }
    }
    const auto slotOf = [&slots](const recordings::DeviceKindBase& kind) {
        for (const auto& s : slots) {
            if (&s->kind() == &kind) {
                return static_cast<const recordings::DeviceSlot*>(s.get());
            }
        }
        return static_cast<const recordings::DeviceSlot*>(nullptr);
    };
    const auto* spectrometer = slotOf(recordings::spectrometerKind());
    const auto* tracker = slotOf(recordings::trackerKind());
    const auto* accel = slotOf(recordings::accelKind());
    const auto* lampSelector = slotOf(recordings::lampSelectorKind());
    pipeline::scene::SceneState state;
    pipeline::render::RenderedFrame image;
    bool stepping = pacing == Pacing::Step;
    auto wallStart = std::chrono::steady_clock::now();
    bool afterWarmup = false;

    for (;;) {
        if (stopRequested()) {
            log->info("stop requested: ending after {} frames", stats.frames);
            break;
        }
        std::optional<TickPlan> nextTick = ticks();
        if (!nextTick) {
            break;
        }
        if (pacing == Pacing::Realtime && options.skipLateTicks) {
            const std::int64_t nowNs = std::chrono::duration_cast<std::chrono::nanoseconds>(
                                               std::chrono::steady_clock::now() - wallStart)
                                               .count();
            const std::uint64_t skip = ticksToSkip(nowNs, nextTick->tickNs, options.periodNs);
            // The plan's last tick is rendered even when late: a fixed run ends on its last frame.
            for (std::uint64_t i = 0; i < skip; ++i) {
                std::optional<TickPlan> later = ticks();
                if (!later) {
                    break;
                }
                nextTick = std::move(later);
                ++stats.skippedTicks;
            }
            if (skip > 0) {
                log->debug("late: skipped {} ticks to frame {}", skip, nextTick->frameIndex);
            }
        }
        const TickPlan& tick = *nextTick;
        if (tick.estimateOnly) {
            afterWarmup = true;
        } else if (pacing == Pacing::Realtime) {
            if (afterWarmup) {
                // Pace from here as if the session had started tickNs ago (a slice's first frame).
                wallStart = std::chrono::steady_clock::now() -
                            std::chrono::nanoseconds(std::min<std::int64_t>(
                                    tick.tickNs, std::int64_t{1'000'000'000} * 86'400 * 365));
                afterWarmup = false;
            }
            // A recording's tick is untrusted (a tick_ns of 9e18 is 285 years away): computed
            // without overflow, and no frame waits more than a second. A live run's ticks are a
            // period apart, at most a second (--rate >= 1), so this never shortens one.
            const std::int64_t elapsed = std::chrono::duration_cast<std::chrono::nanoseconds>(
                                                 std::chrono::steady_clock::now() - wallStart)
                                                 .count();
            if (tick.tickNs < elapsed - 2'000'000) {
                ++stats.lateFrames;
            }
            if (tick.tickNs > elapsed) {
                std::this_thread::sleep_for(std::chrono::nanoseconds(
                        std::min<std::int64_t>(tick.tickNs - elapsed, 1'000'000'000)));
            }
        } else if (stepping) {
            std::string line;
            if (!std::getline(std::cin, line)) {
                stepping = false; // input closed: run the rest without waiting
            }
        }

        const auto workStart = std::chrono::steady_clock::now();
        const bool replaying = tick.recorded.has_value();
        for (auto& slot : slots) {
            const auto& kind = slot->kind();
            if (auto d = slot->poll(tick.tickNs); d > 0) {
                stats.dropped[kind.name()] += d;
                log->warn("{} {}: {} {} dropped before t={} ns", kind.names().displayName,
                          slot->source().info().serial, d, kind.names().samplesNoun, tick.tickNs);
            }
        }
        for (auto& slot : slots) {
            slot->choose(replaying ? tick.recorded->sequence(slot->kind()) : std::nullopt,
                         replaying, stats.replayMismatches);
        }

        state.frameIndex = tick.frameIndex;
        state.tickNs = tick.tickNs;
        appliance.sceneEstimator->update(
                state, recordings::chosenSample<hal::SpectrumSample>(spectrometer),
                recordings::chosenSample<hal::PoseSample>(tracker),
                recordings::chosenSample<hal::AccelSample>(accel),
                recordings::chosenSample<hal::LampSample>(lampSelector));
        if (tick.estimateOnly) {
            // Before a replayed slice: the state stage alone. A frame is a function of its
            // SceneState (the renderer keeps no history), so nothing before the slice is drawn.
            ++stats.estimatedOnly;
            continue;
        }
        if (auto ok = appliance.renderer->render(state, image, readback); !ok) {
            return tl::unexpected(ok.error());
        }
        // Over the surface's pixels: the black panel around a booth surface is below black by
        // construction and would count whatever the booth and the display do.
        const double oog = image.gamut.surfaceOutOfGamutFraction();
        const auto& g = image.gamut;
        const bool surface = g.surfacePixels > 0;
        log->debug("frame {}: {:.4f} of the {} pixels out of gamut (chroma {}, above peak {}, "
                   "below black {})",
                   tick.frameIndex, oog, surface ? "surface's" : "frame's",
                   surface ? g.surfaceChroma : g.chroma, surface ? g.surfaceOverPeak : g.overPeak,
                   surface ? g.surfaceBelowBlack : g.belowBlack);
        stats.sumOutOfGamutFraction += oog;
        stats.maxOutOfGamutFraction = std::max(stats.maxOutOfGamutFraction, oog);
        stats.sumOverPeakFraction += g.surfaceOverPeakFraction();
        stats.maxOverPeakFraction =
                std::max(stats.maxOverPeakFraction, g.surfaceOverPeakFraction());
        DisplayFrame frame{image.width, image.height, image.rgba, image.displayFramebuffer};
        if (auto ok = appliance.output->present(frame); !ok) {
            log->warn("output {}: {}", appliance.output->name(), ok.error().message);
        }

        recordings::FrameRecord record{tick.frameIndex, tick.tickNs, {}};
        for (const auto& slot : slots) {
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
        if (options.afterFrame) {
            options.afterFrame(stats);
        }
        if (options.nextRecorder) {
            auto* next = options.nextRecorder(recorder);
            if (next != recorder && next != nullptr) {
                // The new file starts with what the scene holds now.
                for (const auto& slot : slots) {
                    slot->writeLatest(*next);
                }
                ++stats.recorderRotations;
            }
            recorder = next;
            tee = recorder;
        }
    }
    if (stats.replayMismatches > 0) {
        log->warn("replay: {} recorded samples were missing; the latest sample was used instead",
                  stats.replayMismatches);
    }
    return stats;
}

} // namespace replica::platform
