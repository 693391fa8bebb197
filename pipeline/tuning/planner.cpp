// Planner: enumerate settings by modelled cost, render the probe, stop at the first that meets the
// budget.
#include <algorithm>

#include <pipeline/reference/reference_integrator.h>
#include <pipeline/tuning/planner.h>

namespace replica::pipeline::shading {

double settingCost(const RenderSettings& s, bool glossy, bool relief)
{
    // One point light with cosines ~ 1 unit; with relief a second normal-mapped evaluation plus the
    // horizon interpolation ~ 1.5 units; one FIS sample (sampling, plane hit, trilinear mip read)
    // ~ 6.
    double c = s.lights * 1.0;
    if (relief && s.reliefPass) {
        c += s.lights * 1.5 + 0.25 * s.horizonDirections;
    }
    if (glossy && s.specularPass) {
        c += s.specularSamples * 6.0 *
             (relief && s.reliefPass && s.horizonDirections > 0 ? 1.3 : 1.0);
    }
    return c;
}

std::vector<View> probeViews(const scene::StandModel& stand, int probeX, int probeY)
{
    std::vector<View> views;
    for (double tilt : {10.0, 30.0, 50.0}) {
        for (const Vec3& eye : {Vec3{0.0, 0.45, 0.60}, Vec3{-0.30, 0.40, 0.55}}) {
            View v;
            v.panel = scene::panelPose(stand, scene::degreesToRadians(tilt));
            v.eye = eye;
            v.pixelsX = probeX;
            v.pixelsY = probeY;
            views.push_back(v);
        }
    }
    return views;
}

Plan planRender(const surface::SurfaceScene& scene,
                const booth::BoothLight& light,
                const View& view,
                const colour::Observer& obs,
                const ErrorBudget& budget,
                int probeX,
                int probeY,
                const colour::ChannelBasis& basis)
{
    View probe = view;
    probe.pixelsX = probeX;
    probe.pixelsY = probeY;
    return planRenderViews(scene, light, {probe}, obs, budget, RenderSettings{}, basis);
}

Plan planRenderViews(const surface::SurfaceScene& scene,
                     const booth::BoothLight& light,
                     const std::vector<View>& views,
                     const colour::Observer& obs,
                     const ErrorBudget& budget,
                     const RenderSettings& base,
                     const colour::ChannelBasis& basis)
{
    Plan plan;
    const bool glossy = scene.glossy();
    const bool relief = !scene.flat();
    if (!glossy) {
        plan.skipped.emplace_back("specular: rho_s is zero in every band (matte scene)");
    }
    if (!relief) {
        plan.skipped.emplace_back("normal map and horizon: the height field is flat");
    }
    std::vector<XyzFrame> refs;
    refs.reserve(views.size());
    for (const View& v : views) {
        refs.push_back(reference::renderReference(scene, light, v, obs));
    }

    std::vector<RenderSettings> candidates;
    for (int lights : {8, 16, 32, 64, 128, 256}) {
        for (int samples :
             glossy ? std::vector<int>{1, 4, 8, 12, 16, 24, 32, 48, 64} : std::vector<int>{0}) {
            for (int dirs : relief ? std::vector<int>{8, 16} : std::vector<int>{0}) {
                RenderSettings s = base;
                s.lights = lights;
                s.specularSamples = samples;
                s.specularPass = glossy;
                s.horizonDirections = dirs;
                s.reliefPass = relief;
                candidates.push_back(s);
            }
        }
    }
    std::stable_sort(candidates.begin(), candidates.end(),
                     [&](const RenderSettings& a, const RenderSettings& b) {
                         return settingCost(a, glossy, relief) < settingCost(b, glossy, relief);
                     });
    int preparedLights = -1;
    int preparedDirs = -1;
    PreparedLight pl;
    PreparedScene ps;
    double bestP95 = 1e9;
    for (const RenderSettings& s : candidates) {
        if (s.lights != preparedLights) {
            pl = prepareLight(light, obs, s.lights, basis);
            preparedLights = s.lights;
        }
        if (s.horizonDirections != preparedDirs) {
            ps = prepareScene(scene, std::max(s.horizonDirections, 1), 0.01, basis);
            preparedDirs = s.horizonDirections;
        }
        // The worst over the views; a view past the budget ends the candidate early.
        reference::FrameError worst{0.0, 0.0, 0.0};
        bool within = true;
        for (std::size_t i = 0; i < views.size(); ++i) {
            const XyzFrame f = renderRealtime(ps, pl, views[i], obs, s);
            const reference::FrameError e = reference::compareFrames(refs[i], f);
            worst.mean = std::max(worst.mean, e.mean);
            worst.p95 = std::max(worst.p95, e.p95);
            worst.max = std::max(worst.max, e.max);
            if (!(e.p95 <= budget.p95 && e.max <= budget.max)) {
                within = false;
                break;
            }
        }
        ++plan.evaluated;
        if (within) {
            plan.settings = s;
            plan.probeError = worst;
            plan.relativeCost = settingCost(s, glossy, relief);
            plan.met = true;
            return plan;
        }
        if (worst.p95 < bestP95) {
            bestP95 = worst.p95;
            plan.settings = s;
            plan.probeError = worst;
            plan.relativeCost = settingCost(s, glossy, relief);
        }
    }
    return plan;
}

} // namespace replica::pipeline::shading
