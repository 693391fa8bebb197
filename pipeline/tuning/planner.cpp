// Planner: enumerate settings by modelled cost, render the probe, stop at the first that meets the
// budget.
#include <algorithm>
#include <map>

#include <pipeline/reference/reference_integrator.h>
#include <pipeline/tuning/planner.h>

namespace replica::pipeline::shading {

double settingCost(const RenderSettings& s, bool glossy, bool relief)
{
    // Calibrated on the GL frame: CPU milliseconds (every llvmpipe thread) that each count adds
    // to the appliance's 960x600 frame with the tilt moving (pass 1 recomputing its diffuse term
    // in three bands through the tilt estimator, tests/benchmarks/frame_timing.h; the frame the
    // loop's deadline must hold while the panel moves). Refitted 2026-12-06 on main 7c76def
    // (flat passes loop over the lights with the diffuse grid, df303d4): runs of
    // replica_bench_cost_model --scene colorchecker (7) and --scene painting (5) on the 2-core
    // build machine at load average 5-20, the per-setting median of the runs fitted by least
    // squares (tests/benchmarks/cost_model_pool.py over tests/benchmarks/measured/): the
    // ColorChecker (flat; lights 8/32/128 x samples 4/16/48) 0.113 ms a light, R^2 0.92; the
    // painting (relief; lights 8/32/128 x samples 4/16/48 x directions 8/16) 0.625 a light,
    // 1.31 a horizon direction, 1.58 a sample, R^2 0.96, residual RMS 9.5 ms of 41-201.
    // On flat surfaces the specular term is shaded on the 8-texel grid, so a sample costs
    // nothing measurable (fit -0.030 ms, single runs -0.09 to +0.09): 0.002 ms keeps the fewer
    // samples first among settings of as many lights. Refit: docs/rendering.md, "Planner".
    //
    // The walls (RenderSettings::walls: a biquadratic and a dot product a pixel in the cache
    // pass, and the field baked on the CPU once per pose, so every frame while the tilt moves),
    // from the same runs: 32 lights, 16 samples (8 directions) under the shipped booth and under
    // a copy declaring N7 walls, alternated, the median of the pairs' differences: the
    // ColorChecker 1.1 ms (nine pairs, +0.1 to +5.4), the painting 0.5 ms (three pairs, -0.4
    // to +2.7). (Before: 0.05 and 0.3, the median whole frame of 'replica run --hal sim
    // --no-planner --rate 60 --frames 300', a different frame.) Small, but not zero: walls that
    // change nothing visible are not drawn.
    struct Coefficients {
        double light;
        double direction;
        double sample;
        double walls;
    };
    //
    // Relief on the grids (shading::defaultSpecularGrid and defaultDiffuseGrid where the relief
    // turns slowly: eq. (1) with facets and horizons at the diffuse grid's nodes, the specular
    // term at the specular grid's), refitted 2026-12-07 on main 46dfa05: replica_bench_cost_model
    // --scene glossy-cylinder five runs (one of 9 frames, four of 15; specular grid 2, diffuse
    // grid 4), pooled: 0.040 ms a light, 0.047 a horizon direction, 0.114 a sample, R^2 0.986,
    // residual RMS 0.36 ms of 15-26. Each term takes the grid coefficient when its own grid is
    // on, the per-pixel one when not; the walls are drawn per pixel either way.
    constexpr Coefficients kFlat{0.113, 0.0, 0.002, 1.1};   // area lights, specular, diffuse grids
    constexpr Coefficients kRelief{0.625, 1.31, 1.58, 0.5}; // point lights, per-pixel specular
    constexpr Coefficients kReliefGrids{0.040, 0.047, 0.114, 0.5};
    const bool onRelief = relief && s.reliefPass;
    const Coefficients& k = onRelief ? kRelief : kFlat;
    const Coefficients& diffuse = onRelief && s.diffuseGrid > 0 ? kReliefGrids : k;
    const Coefficients& specular = onRelief && s.specularGrid > 0 ? kReliefGrids : k;
    double c = s.lights * diffuse.light;
    if (onRelief) {
        c += s.horizonDirections * diffuse.direction;
    }
    if (glossy && s.specularPass) {
        c += s.specularSamples * specular.sample;
    }
    if (s.walls) {
        c += k.walls;
    }
    return c;
}

std::vector<View> probeViews(const scene::StandModel& stand, int probeX, int probeY, int eyes)
{
    const std::vector<Vec3> all{{0.0, 0.45, 0.60}, {-0.30, 0.40, 0.55}, {0.30, 0.40, 0.55}};
    const std::vector<Vec3> used(all.begin(), all.begin() + std::clamp(eyes, 1, 3));
    std::vector<View> views;
    for (double tilt : {10.0, 30.0, 50.0}) {
        for (const Vec3& eye : used) {
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

namespace {

// Every setting the planner may pick, cheapest first (settingCost; ties keep this order: fewer
// samples, fewer directions, without the walls first).
std::vector<RenderSettings>
candidateSettings(const RenderSettings& base, bool glossy, bool relief, bool hasWalls)
{
    std::vector<RenderSettings> candidates;
    for (int lights : {8, 16, 32, 64, 128, 256}) {
        for (int samples :
             glossy ? std::vector<int>{1, 4, 8, 12, 16, 24, 32, 48, 64} : std::vector<int>{0}) {
            for (int dirs : relief ? std::vector<int>{8, 16} : std::vector<int>{0}) {
                for (bool withWalls :
                     hasWalls ? std::vector<bool>{false, true} : std::vector<bool>{false}) {
                    RenderSettings s = base;
                    s.lights = lights;
                    s.specularSamples = samples;
                    s.specularPass = glossy;
                    s.horizonDirections = dirs;
                    s.reliefPass = relief;
                    s.walls = withWalls;
                    candidates.push_back(s);
                }
            }
        }
    }
    std::stable_sort(candidates.begin(), candidates.end(),
                     [&](const RenderSettings& a, const RenderSettings& b) {
                         return settingCost(a, glossy, relief) < settingCost(b, glossy, relief);
                     });
    return candidates;
}

} // namespace

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
                     const colour::ChannelBasis& basis,
                     const PlanWalls& walls)
{
    Plan plan;
    const bool hasWalls = walls.exact != nullptr && walls.realtime != nullptr;
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
        reference::ReferenceOptions ro;
        ro.walls = hasWalls ? walls.exact : nullptr;
        refs.push_back(reference::renderReference(scene, light, v, obs, ro));
    }

    const std::vector<RenderSettings> candidates =
            candidateSettings(base, glossy, relief, hasWalls);
    // Prepared once per light count and per horizon direction count: the candidates, in cost
    // order, go back and forth between them (a painting's horizon map takes seconds).
    std::map<int, PreparedLight> lightsPrepared;
    std::map<int, PreparedScene> scenesPrepared;
    double bestP95 = 1e9;
    for (const RenderSettings& s : candidates) {
        auto li = lightsPrepared.find(s.lights);
        if (li == lightsPrepared.end()) {
            li = lightsPrepared.emplace(s.lights, prepareLight(light, obs, s.lights, basis)).first;
        }
        auto si = scenesPrepared.find(s.horizonDirections);
        if (si == scenesPrepared.end()) {
            si = scenesPrepared
                         .emplace(
                                 s.horizonDirections,
                                 prepareScene(scene, std::max(s.horizonDirections, 1), 0.01, basis))
                         .first;
        }
        PreparedLight& pl = li->second;
        pl.walls = s.walls ? walls.realtime : nullptr;
        const PreparedScene& ps = si->second;
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
            if (hasWalls && !s.walls) {
                plan.skipped.emplace_back(
                        "walls: the probe meets the budget without the walls' light");
            }
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
