// The GLES booth pass against the exact reference: the default and planned settings meet the
// error budget (dE00 p95 <= 1, max <= 3) on the shipped scenes.
#include "booth_pass_fixture.h"

namespace replica::pipeline::render {
namespace {

TEST_F(BoothPassTest, FlatSpecularGridMeetsTheErrorBudgetAgainstTheReference)
{
    // What the appliance runs on the ColorChecker: the default setting with the specular term
    // shaded every kFlatSpecularGrid texels and eq. (1) summed every kFlatDiffuseGrid, against
    // the exact reference under every light. (The metamer's budget needs the adaptive basis,
    // not this fixture's fixed one; DiffuseGrid.* bounds what the grid adds there.)
    const shading::View v = view(24, 15);
    const auto& scene = scenes_.at("colorchecker");
    ASSERT_EQ(shading::defaultSpecularGrid(scene), shading::kFlatSpecularGrid);
    ASSERT_EQ(shading::defaultDiffuseGrid(scene), shading::kFlatDiffuseGrid);
    ASSERT_EQ(shading::defaultSpecularGrid(scenes_.at("painting")), 0);
    shading::RenderSettings settings;
    settings.specularGrid = shading::kFlatSpecularGrid;
    settings.diffuseGrid = shading::kFlatDiffuseGrid;
    expectWithinBudget(scene, settings, {v});
}

TEST_F(BoothPassTest, ReliefDefaultSampleCountMeetsTheErrorBudgetAgainstTheReference)
{
    // What the appliance runs on the painting: per pixel, with the relief's default sample count
    // (fewer than a flat surface's, since each sample costs every pixel), against the exact
    // reference under every light.
    const shading::View v = view(24, 15);
    const auto& scene = scenes_.at("painting");
    ASSERT_EQ(shading::defaultSpecularSamples(scene), shading::kReliefSpecularSamples);
    ASSERT_EQ(shading::defaultSpecularSamples(scenes_.at("colorchecker")),
              shading::kFlatSpecularSamples);
    ASSERT_LT(shading::kReliefSpecularSamples, shading::kFlatSpecularSamples);
    shading::RenderSettings settings;
    settings.specularSamples = shading::defaultSpecularSamples(scene);
    settings.specularGrid = shading::defaultSpecularGrid(scene);
    expectWithinBudget(scene, settings, {v});
}

TEST_F(BoothPassTest, FlatDefaultSampleCountMeetsTheBudgetWhereTheTubesAlias)
{
    // The ColorChecker leaning back 50 degrees under the d50 tubes, seen from the centre and
    // from the left: there the tubes' reflection aliases against the sample pattern, and the
    // 12 samples that met the budget from the sweep's one view reached p95 1.07-1.09 on the
    // 64x40 frame (replica_bench_render --views; 16 samples 1.29). The default, on the grid the
    // appliance shades it on, must meet the budget from both eyes: measured p95 0.63 / 0.75 at
    // 24 samples on this 32x20 frame, 1.005 / 1.015 at 12.
    const auto& scene = scenes_.at("colorchecker");
    shading::RenderSettings settings;
    settings.specularSamples = shading::defaultSpecularSamples(scene);
    settings.specularGrid = shading::defaultSpecularGrid(scene);
    settings.diffuseGrid = shading::defaultDiffuseGrid(scene);
    std::vector<shading::View> views;
    for (const shading::Vec3 eye :
         {shading::Vec3(0.0, 0.45, 0.60), shading::Vec3(-0.30, 0.40, 0.55)}) {
        views.push_back(view(32, 20, 50.0));
        views.back().eye = eye;
    }
    expectWithinBudget(scene, settings, views, "d50-fluorescent");
}

TEST_F(BoothPassTest, PlannedSettingMeetsTheErrorBudgetAgainstTheReference)
{
    // The budget: dE00 95th <= 1, max <= 3. The settings are what shading::planRender
    // picks for these scenes under d65-fluorescent on its 32x20 probe (replica render --plan;
    // docs/rendering.md); running the planner here would take half a minute. The GL pass with
    // that setting must meet the budget against the exact reference on a different frame
    // (24x15: the reference integrates every luminance texel for every pixel; at 20x12 a row of
    // pixel centres falls exactly on a texel edge of the painting, texY = 60.0, where float and
    // double pick different texels).
    const shading::View v = view(24, 15);
    struct Case {
        const char* scene;
        int lights, samples, dirs;
    };
    for (const Case c : {Case{"colorchecker", 32, 8, 0}, Case{"painting", 32, 4, 8}}) {
        const auto& scene = scenes_.at(c.scene);
        const auto& light = booth_->lights[2]; // d65-fluorescent: tubes, the hardest image
        shading::RenderSettings settings;
        settings.lights = c.lights;
        settings.specularSamples = c.samples;
        settings.horizonDirections = c.dirs;
        const auto ps = shading::prepareScene(scene, std::max(settings.horizonDirections, 1), 0.01,
                                              *basis_);
        auto pass = BoothShadingPass::create(ps, settings, *obs_);
        ASSERT_TRUE(pass) << pass.error().message;
        const auto pl = shading::prepareLight(light, *obs_, settings.lights, *basis_);
        ASSERT_TRUE((*pass)->setLight(pl));
        const auto e = errorAgainstReference(**pass, pl, scene, light, v);
        EXPECT_LE(e.p95, 1.0) << c.scene;
        EXPECT_LE(e.max, 3.0) << c.scene;
    }
}

} // namespace
} // namespace replica::pipeline::render
