// Picks the cheapest renderer setting that meets an error budget for the scene and light in hand,
// measured against the exact reference on a small probe frame; skips passes the scene does not
// need.
#pragma once

#include <string>
#include <vector>

#include <pipeline/reference/frame_error.h>
#include <pipeline/shading/realtime_model.h>

namespace replica::pipeline::shading {

struct ErrorBudget {
    double p95 = 1.0; // CIEDE2000, 95th percentile over the probe frame
    double max = 3.0;
};

struct Plan {
    RenderSettings settings;
    reference::FrameError probeError; // of the chosen setting on the probe frame
    double relativeCost = 0.0;        // cost model units per pixel (see planner.cpp)
    bool met = false;                 // false: nothing met the budget; settings = the most accurate
    std::vector<std::string> skipped; // passes not needed, with the reason
    int evaluated = 0;
};

// Cost model per pixel, in units of one point-light evaluation (calibrated on the CPU model).
double settingCost(const RenderSettings& s, bool glossy, bool relief);

Plan planRender(const surface::SurfaceScene& scene,
                const booth::BoothLight& light,
                const View& view,
                const colour::Observer& obs,
                const ErrorBudget& budget = {},
                int probeX = 32,
                int probeY = 20,
                const colour::ChannelBasis& basis = colour::boxBasis());

} // namespace replica::pipeline::shading
