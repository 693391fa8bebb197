// Timing the appliance's whole frame, as the whole-frame benchmarks (pareto, cost model) share it:
// the process's CPU time beside the wall clock, the median and spread of a series, and one run of
// eye-moving then tilt-moving frames through the state stage's tilt estimator.
#pragma once

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstddef>
#include <cstdio>
#include <numbers>
#include <vector>

#include <state/tilt_estimator.h>
#include <time.h>

#include <platform/appliance.h>

namespace replica::bench {

// CPU time of the whole process (every llvmpipe thread), ms: unlike the wall clock it does not
// count the time other processes on a shared machine take from this one.
inline double cpuMs()
{
    timespec t{};
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
    return static_cast<double>(t.tv_sec) * 1e3 + static_cast<double>(t.tv_nsec) * 1e-6;
}

struct Timing {
    double median = 0.0;
    double p10 = 0.0;
    double p90 = 0.0;
};

// Quantiles by linear interpolation between order statistics; zeros for an empty series.
inline Timing summarise(std::vector<double> ms)
{
    if (ms.empty()) {
        return {};
    }
    std::sort(ms.begin(), ms.end());
    const auto at = [&](double q) {
        const double r = q * static_cast<double>(ms.size() - 1);
        const auto i = static_cast<std::size_t>(std::floor(r));
        const std::size_t j = std::min(i + 1, ms.size() - 1);
        return ms[i] + (r - static_cast<double>(i)) * (ms[j] - ms[i]);
    };
    return {at(0.5), at(0.1), at(0.9)};
}

struct FrameTimes {
    Timing wall;
    Timing cpu;
};

// The appliance's frame under its lamp 'lampIndex', timed: 'frames' frames after three warm-up
// frames, the eye moving with the tilt still at 30 degrees (pass 1 from its cache), then the tilt
// moving one degree a frame between 20 and 40 (pass 1 refreshing its diffuse term in the bands the
// loop draws). The held and diffuse tilts come from the tilt estimator, as the appliance's state
// stage gives them. False, with a line on stderr, when a warm-up frame fails.
inline bool
timeFrames(platform::Appliance& app, int lampIndex, int frames, FrameTimes& eye, FrameTimes& tilt)
{
    const auto rad = [](double deg) { return deg * std::numbers::pi / 180.0; };
    const auto& lamp = app.booth.lights[static_cast<std::size_t>(lampIndex)];
    pipeline::scene::SceneState state;
    state.lampIndex = lampIndex;
    state.illuminant = lamp.referenceSpectrum;
    state.emitterLuminanceCdM2 = lamp.nominalLuminanceCdM2;
    state.tiltRad = rad(30.0);
    pipeline::render::RenderedFrame frame;
    state::TiltEstimator tilts({0.0, app.config.cacheSlices});
    const auto estimate = [&](bool lightChanged) {
        state.lightChanged = lightChanged;
        tilts.sense(state.tiltRad);
        tilts.write(state);
    };
    for (int i = 0; i < 3; ++i) {
        estimate(i == 0);
        if (!app.renderer->render(state, frame, pipeline::render::Readback::Display)) {
            std::fprintf(stderr, "frame failed\n");
            return false;
        }
    }
    std::vector<double> eyeMs, tiltMs, eyeCpu, tiltCpu;
    const auto timed = [&](std::vector<double>& wall, std::vector<double>& cpu) {
        estimate(false);
        const double c0 = cpuMs();
        const auto t0 = std::chrono::steady_clock::now();
        (void)app.renderer->render(state, frame, pipeline::render::Readback::Display);
        wall.push_back(
                std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0)
                        .count());
        cpu.push_back(cpuMs() - c0);
    };
    double t = 0.0;
    for (int i = 0; i < frames; ++i) {
        t += 1.0 / 60.0;
        state.eyeBoothM.x = 0.25 * std::sin(t); // the viewer walks past
        timed(eyeMs, eyeCpu);
    }
    for (int i = 0; i < frames; ++i) {
        const int phase = i % 40;
        state.tiltRad = rad(20.0 + (phase < 20 ? phase : 40 - phase));
        timed(tiltMs, tiltCpu);
    }
    eye = {summarise(eyeMs), summarise(eyeCpu)};
    tilt = {summarise(tiltMs), summarise(tiltCpu)};
    return true;
}

} // namespace replica::bench
