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

// The probe's views: the panel at tilts 10, 30 and 50 degrees seen from 'eyes' eyes (1-3: the
// centre, off to the left, off to the right; two are render_bench's --views eyes), so a setting
// must meet the budget at the grazing tilt where the horizons matter and at the steep one where
// the highlights move, not on one view. The worst p95 and the worst max over them decide.
std::vector<View>
probeViews(const scene::StandModel& stand, int probeX = 32, int probeY = 20, int eyes = 2);

// The booth's walls under the light being planned, solved twice (reference::solveWalls): 'exact'
// at the reference's patches, the truth every candidate is measured against; 'realtime' at the
// appliance's patches, what a candidate with RenderSettings::walls draws. Both null: a booth
// without walls, whose candidates never light with them.
struct PlanWalls {
    const booth::WallLight* exact = nullptr;
    const booth::WallLight* realtime = nullptr;
};

struct Plan {
    RenderSettings settings;
    reference::FrameError probeError; // of the chosen setting: worst p95 and max over the views
    double relativeCost = 0.0;        // settingCost: modelled ms (see planner.cpp)
    bool met = false;                 // false: nothing met the budget; settings = the most accurate
    std::vector<std::string> skipped; // passes not needed, with the reason
    int evaluated = 0;
};

// Cost model: the milliseconds the setting's lights, horizon directions and specular samples add
// to the appliance's 960x600 frame with the tilt moving, calibrated on llvmpipe's GL frame
// (planner.cpp says how and how to refit). Only its order matters to the planner.
double settingCost(const RenderSettings& s, bool glossy, bool relief);

// The cheapest setting (by settingCost) whose worst p95 and max over 'views' meet the budget.
// 'base' gives everything but lights, specular samples, horizon directions and walls (grids, area
// lights, mip rules: the appliance's own), so the probe measures what the appliance will draw.
// With 'walls' the reference lights the surface from the booth's walls too, and each candidate is
// tried without them and with them: the walls are drawn where leaving them out would cost the
// budget.
Plan planRenderViews(const surface::SurfaceScene& scene,
                     const booth::BoothLight& light,
                     const std::vector<View>& views,
                     const colour::Observer& obs,
                     const ErrorBudget& budget,
                     const RenderSettings& base,
                     const colour::ChannelBasis& basis,
                     const PlanWalls& walls = {});

// One view ('replica render --plan'): planRenderViews on 'view' at probeX x probeY.
Plan planRender(const surface::SurfaceScene& scene,
                const booth::BoothLight& light,
                const View& view,
                const colour::Observer& obs,
                const ErrorBudget& budget = {},
                int probeX = 32,
                int probeY = 20,
                const colour::ChannelBasis& basis = colour::boxBasis());

} // namespace replica::pipeline::shading
