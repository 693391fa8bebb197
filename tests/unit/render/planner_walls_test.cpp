// The planner under a booth with walls: the probe's truth is the reference with the walls, and a
// lamp draws them where leaving them out would cost the budget. Grey N7 walls change the
// ColorChecker by about ΔE00 1 (docs/rendering.md), past the appliance's probe budget, so the
// planner draws them; walls of 2 % reflectance change it by far less, so it leaves them out and
// says why. Each pick is checked by rendering it again (with and without the walls) against the
// reference with the walls.
#include <algorithm>
#include <string>

#include <pipeline/base/data_dir.h>
#include <pipeline/booth/booth_model.h>
#include <pipeline/reference/frame_error.h>
#include <pipeline/reference/reference_integrator.h>
#include <pipeline/reference/wall_radiosity.h>
#include <pipeline/scene/booth.h>
#include <pipeline/spectral/adaptive_encoding.h>
#include <pipeline/surface/surface_scene.h>
#include <pipeline/tuning/planner.h>

#include <gtest/gtest.h>

#include "render_fixtures.h"

namespace replica::pipeline {
namespace {

// The appliance's probe budget (platform/render_plan.h: ΔE00 p95 1, max 3, with a margin of 0.75).
constexpr shading::ErrorBudget kProbeBudget{0.75, 2.25};

struct WallsUnderTest {
    booth::BoothLight light;
    booth::WallLight exact;
    booth::WallLight realtime;
    colour::ChannelBasis basis; // the appliance's: adaptive_k6 for this light
};

WallsUnderTest solvedWalls(double reflectance)
{
    auto b = booth::loadBooth(dataDir() / "booth");
    EXPECT_TRUE(b) << b.error().message;
    const booth::BoothLight& light = *b->find("d65");
    booth::BoothWalls walls = scene::defaultBoothWalls(light);
    if (reflectance >= 0.0) {
        walls.reflectance = colour::Spectrum::constant(reflectance);
    }
    reference::WallSolveOptions exact;
    exact.patchM = 0.1; // converged to about 1 % (wall_reference_test.cpp); fast enough here
    reference::WallSolveOptions coarse;
    coarse.patchM = 0.35; // the appliance's (render::kRealtimeWallPatchM)
    auto encoder = spectral::AdaptiveEncoder::createDefault(dataDir());
    EXPECT_TRUE(encoder) << encoder.error().message;
    auto basis = encoder->basisFor(light.spd);
    EXPECT_TRUE(basis) << basis.error().message;
    return {light, reference::solveWalls(walls, light, test::observer(), exact),
            reference::solveWalls(walls, light, test::observer(), coarse), *basis};
}

const surface::SurfaceScene& checker()
{
    static const surface::SurfaceScene s = [] {
        auto scene = surface::loadScene(dataDir() / "scenes" / "colorchecker");
        EXPECT_TRUE(scene) << scene.error().message;
        return *scene;
    }();
    return s;
}

// The worst p95 and max over the views of 's' against the reference with the walls.
reference::FrameError errorAgainstWalls(const WallsUnderTest& w,
                                        const std::vector<shading::View>& views,
                                        shading::RenderSettings s)
{
    const auto ps = shading::prepareScene(checker(), 1, 0.01, w.basis);
    auto pl = shading::prepareLight(w.light, test::observer(), s.lights, w.basis);
    pl.walls = s.walls ? &w.realtime : nullptr;
    reference::ReferenceOptions ro;
    ro.walls = &w.exact;
    reference::FrameError worst{0.0, 0.0, 0.0};
    for (const auto& v : views) {
        const auto ref = reference::renderReference(checker(), w.light, v, test::observer(), ro);
        const auto e = reference::compareFrames(
                ref, shading::renderRealtime(ps, pl, v, test::observer(), s));
        worst.p95 = std::max(worst.p95, e.p95);
        worst.max = std::max(worst.max, e.max);
    }
    return worst;
}

shading::RenderSettings base()
{
    shading::RenderSettings s;
    s.specularGrid = shading::defaultSpecularGrid(checker());
    s.diffuseGrid = shading::defaultDiffuseGrid(checker());
    s.areaLights = shading::defaultAreaLights(checker());
    return s;
}

// The planner's probe here: three tilts from the centre eye at 16 x 10 pixels.
std::vector<shading::View> probe()
{
    return shading::probeViews(scene::StandModel{}, 16, 10, 1);
}

shading::Plan
planWith(const WallsUnderTest& w, const std::vector<shading::View>& views, shading::PlanWalls walls)
{
    return shading::planRenderViews(checker(), w.light, views, test::observer(), kProbeBudget,
                                    base(), w.basis, walls);
}

TEST(PlannerWalls, GreyWallsAreDrawnBecauseLeavingThemOutCostsTheBudget)
{
    const WallsUnderTest w = solvedWalls(-1.0); // N7, the default
    const auto views = probe();
    const shading::Plan plan = planWith(w, views, {&w.exact, &w.realtime});
    ASSERT_TRUE(plan.met);
    EXPECT_TRUE(plan.settings.walls);
    // The pick holds against the truth with walls; the same setting without them does not.
    const auto with = errorAgainstWalls(w, views, plan.settings);
    EXPECT_LE(with.p95, kProbeBudget.p95);
    EXPECT_LE(with.max, kProbeBudget.max);
    EXPECT_NEAR(with.p95, plan.probeError.p95, 1e-9);
    shading::RenderSettings without = plan.settings;
    without.walls = false;
    const auto missed = errorAgainstWalls(w, views, without);
    EXPECT_GT(missed.p95, kProbeBudget.p95);
    // Nothing says the walls were skipped.
    for (const auto& why : plan.skipped) {
        EXPECT_EQ(why.find("walls"), std::string::npos) << why;
    }
}

TEST(PlannerWalls, NearlyBlackWallsAreLeftOutAndThePlanSaysWhy)
{
    const WallsUnderTest w = solvedWalls(0.02);
    const auto views = probe();
    const shading::Plan plan = planWith(w, views, {&w.exact, &w.realtime});
    ASSERT_TRUE(plan.met);
    EXPECT_FALSE(plan.settings.walls);
    const auto e = errorAgainstWalls(w, views, plan.settings);
    EXPECT_LE(e.p95, kProbeBudget.p95);
    EXPECT_LE(e.max, kProbeBudget.max);
    const bool said = std::any_of(plan.skipped.begin(), plan.skipped.end(),
                                  [](const auto& why) { return why.rfind("walls:", 0) == 0; });
    EXPECT_TRUE(said);
    // Walls cost a little in the model: the same counts with them sort after those without.
    shading::RenderSettings on = plan.settings;
    on.walls = true;
    EXPECT_GT(shading::settingCost(on, false, false),
              shading::settingCost(plan.settings, false, false));
}

TEST(PlannerWalls, WithoutWallsNoCandidateDrawsThem)
{
    const WallsUnderTest w = solvedWalls(-1.0);
    // Only one of the two solutions: the booth has no walls to plan with.
    const shading::Plan plan = planWith(w, probe(), {&w.exact, nullptr});
    EXPECT_TRUE(plan.met);
    EXPECT_FALSE(plan.settings.walls);

    for (const auto& why : plan.skipped) {
        EXPECT_EQ(why.find("walls"), std::string::npos) << why;
    }
}

} // namespace
} // namespace replica::pipeline
