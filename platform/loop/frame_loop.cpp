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
#include <platform/loop/sample_latch.h>

namespace replica::platform {
namespace {

template <typename Sample>
const Sample* choose(const SampleLatch<Sample>& latch,
                     const std::optional<std::uint32_t>& wanted,
                     bool replaying,
                     std::uint64_t& mismatches)
{
    if (!replaying) {
        return latch.latest();
    }
    if (!wanted) {
        return nullptr; // the original frame had no sample of this device yet
    }
    if (const Sample* s = latch.find(*wanted)) {
        return s;
    }
    ++mismatches;
    return latch.latest();
}

template <typename Sample>
void recordAll(recordings::RecordingWriter* recorder, const std::vector<Sample>& fresh)
{
    if (recorder == nullptr) {
        return;
    }
    for (const auto& s : fresh) {
        recorder->write(s);
    }
}

template <typename Sample>
std::optional<std::uint32_t> sequenceOf(const Sample* s)
{
    return s != nullptr ? std::optional<std::uint32_t>(s->sequence) : std::nullopt;
}

volatile std::sig_atomic_t gStop = 0;

extern "C" void onStopSignal(int)
{
    gStop = 1;
}

} // namespace

void requestStop()
{
    gStop = 1;
}

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
}

TickSource endlessTicks(std::int64_t periodNs)
{
    auto k = std::make_shared<std::uint64_t>(0);
    return [periodNs, k]() -> std::optional<TickPlan> {
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

Expected<LoopStats> runFrames(Appliance& appliance,
                              Sources& sources,
                              const TickSource& ticks,
                              Pacing pacing,
                              recordings::RecordingWriter* recorder,
                              pipeline::render::Readback readback,
                              const FrameCallback& onFrame)
{
    auto log = logger("loop");
    LoopStats stats;
    SampleLatch<hal::SpectrumSample> spectra;
    SampleLatch<hal::PoseSample> poses;
    SampleLatch<hal::AccelSample> accels;
    SampleLatch<hal::LampSample> selector;
    std::vector<hal::SpectrumSample> freshSpectra;
    std::vector<hal::PoseSample> freshPoses;
    std::vector<hal::AccelSample> freshAccel;
    std::vector<hal::LampSample> freshLamp;
    pipeline::scene::SceneState state;
    pipeline::render::RenderedFrame image;
    bool stepping = pacing == Pacing::Step;
    const auto wallStart = std::chrono::steady_clock::now();

    for (;;) {
        if (stopRequested()) {
            log->info("stop requested: ending after {} frames", stats.frames);
            break;
        }
        const std::optional<TickPlan> nextTick = ticks();
        if (!nextTick) {
            break;
        }
        const TickPlan& tick = *nextTick;
        if (pacing == Pacing::Realtime) {
            const auto due = wallStart + std::chrono::nanoseconds(tick.tickNs);
            if (std::chrono::steady_clock::now() > due + std::chrono::milliseconds(2)) {
                ++stats.lateFrames;
            }
            std::this_thread::sleep_until(due);
        } else if (stepping) {
            std::string line;
            if (!std::getline(std::cin, line)) {
                stepping = false; // input closed: run the rest without waiting
            }
        }

        const auto workStart = std::chrono::steady_clock::now();
        freshSpectra.clear();
        freshPoses.clear();
        freshAccel.clear();
        freshLamp.clear();
        sources.spectrometer->poll(tick.tickNs, freshSpectra);
        sources.tracker->poll(tick.tickNs, freshPoses);
        sources.accel->poll(tick.tickNs, freshAccel);
        if (sources.lampSelector) {
            sources.lampSelector->poll(tick.tickNs, freshLamp);
        }
        recordAll(recorder, freshSpectra);
        recordAll(recorder, freshPoses);
        recordAll(recorder, freshAccel);
        recordAll(recorder, freshLamp);
        if (auto d = spectra.push(freshSpectra); d > 0) {
            stats.droppedSpectra += d;
            log->warn("spectrometer {}: {} spectra dropped before t={} ns",
                      sources.spectrometer->info().serial, d, tick.tickNs);
        }
        if (auto d = poses.push(freshPoses); d > 0) {
            stats.droppedPoses += d;
            log->warn("tracker {}: {} poses dropped before t={} ns", sources.tracker->info().serial,
                      d, tick.tickNs);
        }
        if (auto d = accels.push(freshAccel); d > 0) {
            stats.droppedAccel += d;
            log->warn("accelerometer {}: {} samples dropped before t={} ns",
                      sources.accel->info().serial, d, tick.tickNs);
        }
        if (auto d = selector.push(freshLamp); d > 0) {
            stats.droppedLamp += d;
            log->warn("lamp selector {}: {} samples dropped before t={} ns",
                      sources.lampSelector->info().serial, d, tick.tickNs);
        }

        const bool replaying = tick.recorded.has_value();
        const auto& rec = tick.recorded;
        const hal::SpectrumSample* s =
                choose(spectra, replaying ? rec->spectrumSequence : std::nullopt, replaying,
                       stats.replayMismatches);
        const hal::PoseSample* p = choose(poses, replaying ? rec->poseSequence : std::nullopt,
                                          replaying, stats.replayMismatches);
        const hal::AccelSample* a = choose(accels, replaying ? rec->accelSequence : std::nullopt,
                                           replaying, stats.replayMismatches);
        const hal::LampSample* l = choose(selector, replaying ? rec->lampSequence : std::nullopt,
                                          replaying, stats.replayMismatches);

        state.frameIndex = tick.frameIndex;
        state.tickNs = tick.tickNs;
        appliance.updater->update(state, s, p, a, l);
        if (auto ok = appliance.renderer->render(state, image, readback); !ok) {
            return tl::unexpected(ok.error());
        }
        const double oog = image.gamut.outOfGamutFraction();
        log->debug("frame {}: {:.4f} of pixels out of gamut (chroma {}, above peak {}, below "
                   "black {})",
                   tick.frameIndex, oog, image.gamut.chroma, image.gamut.overPeak,
                   image.gamut.belowBlack);
        stats.sumOutOfGamutFraction += oog;
        stats.maxOutOfGamutFraction = std::max(stats.maxOutOfGamutFraction, oog);
        DisplayFrame frame{image.width, image.height, image.rgba, image.displayFramebuffer};
        if (auto ok = appliance.output->present(frame); !ok) {
            log->warn("output {}: {}", appliance.output->name(), ok.error().message);
        }

        recordings::FrameRecord record{tick.frameIndex, tick.tickNs,   sequenceOf(s),
                                       sequenceOf(p),   sequenceOf(a), sequenceOf(l)};
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
    }
    if (stats.replayMismatches > 0) {
        log->warn("replay: {} recorded samples were missing; the latest sample was used instead",
                  stats.replayMismatches);
    }
    return stats;
}

} // namespace replica::platform
