// The GLES booth pass on the real headless EGL path against the CPU model it follows
// (shading::renderRealtime) and against the exact reference, on every shipped scene.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <map>
#include <numbers>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <glm/geometric.hpp>

#include <pipeline/base/data_dir.h>
#include <pipeline/booth/booth_model.h>
#include <pipeline/reference/frame_error.h>
#include <pipeline/reference/reference_integrator.h>
#include <pipeline/render/booth_shading_pass.h>
#include <pipeline/spectral/adaptive_encoding.h>

#include <gtest/gtest.h>

#include "../support/headless_gl.h"
#include "render_fixtures.h"

namespace replica::pipeline::render {
namespace {

// Float (shader) against double (model): the largest relative difference of any pixel's Y,
// counted over pixels brighter than 1% of the white, and CIEDE2000 between the two frames.
struct Agreement {
    double maxRelY = 0.0;
    double fracOverTol = 0.0; // share of pixels with a relative Y difference above kRelTol
    reference::FrameError de;
};
constexpr double kRelTol = 1e-4;

Agreement agree(const shading::XyzFrame& cpu, const shading::XyzFrame& gl)
{
    Agreement a;
    long over = 0, counted = 0;
    for (std::size_t i = 0; i < cpu.xyz.size(); ++i) {
        const double ref = cpu.xyz[i].y;
        if (ref < 0.01 * cpu.whiteY) {
            continue;
        }
        const double rel = std::abs(gl.xyz[i].y - ref) / ref;
        a.maxRelY = std::max(a.maxRelY, rel);
        over += rel > kRelTol ? 1 : 0;
        ++counted;
    }
    a.fracOverTol = counted > 0 ? static_cast<double>(over) / static_cast<double>(counted) : 1.0;
    a.de = reference::compareFrames(cpu, gl);
    return a;
}

class BoothPassTest : public tests::HeadlessGlTest
{
protected:
    static void SetUpTestSuite()
    {
        obs_ = new colour::Observer(*colour::loadCie1931(dataDir()));
        booth_ = new booth::Booth(*booth::loadBooth(dataDir() / "booth"));
        basis_ = new colour::ChannelBasis(*colour::loadDefaultChannelBasis(dataDir()));
        for (const char* name : {"colorchecker", "metamer", "painting", "glossy-cylinder"}) {
            auto s = surface::loadScene(dataDir() / "scenes" / name);
            ASSERT_TRUE(s) << s.error().message;
            scenes_[name] = *s;
        }
    }
    static void TearDownTestSuite()
    {
        delete obs_;
        delete booth_;
        delete basis_;
        scenes_.clear();
    }
    // The default settings with the painting's specular sample count: what the horizon tests
    // below vary one setting of.
    static shading::RenderSettings paintingSettings()
    {
        shading::RenderSettings settings;
        settings.specularSamples = shading::defaultSpecularSamples(scenes_.at("painting"));
        return settings;
    }

    static shading::View view(int w, int h, double tiltDeg = 30.0)
    {
        shading::View v;
        v.panel = scene::panelPose(scene::degreesToRadians(tiltDeg));
        v.pixelsX = w;
        v.pixelsY = h;
        return v;
    }

    // The GL pass's frame of 'light' (already set on the pass) against the exact reference's.
    static reference::FrameError errorAgainstReference(BoothShadingPass& pass,
                                                       const shading::PreparedLight& pl,
                                                       const surface::SurfaceScene& scene,
                                                       const booth::BoothLight& light,
                                                       const shading::View& v)
    {
        auto gl = renderBoothFrame(pass, pl, v);
        EXPECT_TRUE(gl) << gl.error().message;
        if (!gl) {
            return {1e9, 1e9, 1e9}; // fails every budget below
        }
        return reference::compareFrames(reference::renderReference(scene, light, v, *obs_), *gl);
    }

    // The GL pass with 'settings' on 'scene' against the CPU model under tungsten and
    // d65-fluorescent (every booth light with 'everyLight'). Stated tolerance: float against
    // double agrees to 1e-4 in Y on all but 0.2% of the pixels (where a cosine or horizon test may
    // sit on its threshold), and to 0.01 dE00 at most, 0.001 on average; the white the frame is
    // judged against is the same. 'label' names the case in a failure. 'hardwareFilter', when
    // given, receives whether the pass filters the luminance chain with the sampler; 'glFrames',
    // the GL frames in the order of the lights.
    static void expectMatchesTheCpuModel(const surface::SurfaceScene& scene,
                                         const shading::RenderSettings& settings,
                                         const shading::View& v,
                                         const std::string& label,
                                         bool everyLight = false,
                                         bool* hardwareFilter = nullptr,
                                         std::vector<shading::XyzFrame>* glFrames = nullptr)
    {
        const auto ps = shading::prepareScene(scene, settings.horizonDirections, 0.01, *basis_);
        auto pass = BoothShadingPass::create(ps, settings, *obs_);
        ASSERT_TRUE(pass) << pass.error().message;
        if (hardwareFilter != nullptr) {
            *hardwareFilter = (*pass)->hardwareFilter();
        }
        for (std::size_t i = 0; i < booth_->lights.size(); ++i) {
            if (!everyLight && i != 0 && i != 2) {
                continue; // tungsten and d65-fluorescent
            }
            const auto& light = booth_->lights[i];
            const auto pl = shading::prepareLight(light, *obs_, settings.lights, *basis_);
            ASSERT_TRUE((*pass)->setLight(pl));
            const auto cpu = shading::renderRealtime(ps, pl, v, *obs_, settings);
            auto gl = renderBoothFrame(**pass, pl, v);
            ASSERT_TRUE(gl) << gl.error().message;
            EXPECT_EQ(gl->nonFinite, 0);
            EXPECT_DOUBLE_EQ(gl->whiteY, cpu.whiteY) << label << " / " << light.name;
            const Agreement a = agree(cpu, *gl);
            EXPECT_LE(a.fracOverTol, 0.002)
                    << label << " / " << light.name << " max rel " << a.maxRelY;
            EXPECT_LE(a.de.max, 0.01) << label << " / " << light.name;
            EXPECT_LE(a.de.mean, 0.001) << label << " / " << light.name;
            if (glFrames != nullptr) {
                glFrames->push_back(std::move(*gl));
            }
        }
    }

    // The GL pass with 'settings' on 'scene' under every booth light (or only the one named
    // 'onlyLight') against the exact reference from each of 'views': the budget, dE00 p95
    // <= 1 and max <= 3.
    static void expectWithinBudget(const surface::SurfaceScene& scene,
                                   const shading::RenderSettings& settings,
                                   const std::vector<shading::View>& views,
                                   const std::string& onlyLight = {})
    {
        const auto ps = shading::prepareScene(scene, settings.horizonDirections, 0.01, *basis_);
        auto pass = BoothShadingPass::create(ps, settings, *obs_);
        ASSERT_TRUE(pass) << pass.error().message;
        int lights = 0;
        for (const auto& light : booth_->lights) {
            if (!onlyLight.empty() && light.name != onlyLight) {
                continue;
            }
            ++lights;
            const auto pl = shading::prepareLight(light, *obs_, settings.lights, *basis_);
            ASSERT_TRUE((*pass)->setLight(pl));
            for (const shading::View& v : views) {
                const auto e = errorAgainstReference(**pass, pl, scene, light, v);
                EXPECT_LE(e.p95, 1.0) << scene.name << ", " << light.name << ", eye x " << v.eye.x;
                EXPECT_LE(e.max, 3.0) << scene.name << ", " << light.name << ", eye x " << v.eye.x;
            }
        }
        EXPECT_GT(lights, 0) << "no booth light named " << onlyLight;
    }

    // Alpha 0 to 2, a single hot texel, a zero image, a light almost in the surface plane, tilts
    // 0-135 deg, an eye behind the screen: no NaN or Inf in a read-back pixel, no negative Y.
    static void expectHardCasesFinite(surface::SurfaceScene scene,
                                      const shading::RenderSettings& settings);

    static colour::Observer* obs_;
    static booth::Booth* booth_;
    static colour::ChannelBasis* basis_;
    static std::map<std::string, surface::SurfaceScene> scenes_;
};

colour::Observer* BoothPassTest::obs_ = nullptr;
booth::Booth* BoothPassTest::booth_ = nullptr;
colour::ChannelBasis* BoothPassTest::basis_ = nullptr;
std::map<std::string, surface::SurfaceScene> BoothPassTest::scenes_;

TEST_F(BoothPassTest, MatchesTheCpuModelOnEveryShippedSceneAndLight)
{
    // The default setting (32 lights, 48 samples, 8 horizons), with the luminance chain filtered
    // by the sampler where the GL can (llvmpipe can), else by hand in the shader. Measured: 1e-5
    // relative in Y and 2e-4 dE00 at most on the shipped scenes.
    shading::RenderSettings settings;
    const shading::View v = view(64, 40);
    for (const auto& [name, scene] : scenes_) {
        bool sampler = false;
        expectMatchesTheCpuModel(scene, settings, v, name, true, &sampler);
        RecordProperty(name + "_mip_filter", sampler ? "sampler" : "shader");
    }
}

TEST_F(BoothPassTest, SpecularGridMatchesTheCpuModel)
{
    // The grid pass (mode 2) and the compose's interpolation against the model's: the flat
    // ColorChecker at the appliance's spacing, the painting's relief (facets and horizons at the
    // nodes) at 1 and 3 texels, the glossy cylinder at the spacing its smooth relief gets (2).
    const shading::View v = view(64, 40);
    struct Case {
        const char* scene;
        int grid;
    };
    for (const Case c :
         {Case{"colorchecker", shading::kFlatSpecularGrid}, Case{"painting", 1},
          Case{"painting", 3},
          Case{"glossy-cylinder", shading::defaultSpecularGrid(scenes_.at("glossy-cylinder"))}}) {
        shading::RenderSettings settings;
        settings.specularGrid = c.grid;
        expectMatchesTheCpuModel(scenes_.at(c.scene), settings, v,
                                 std::string(c.scene) + " grid " + std::to_string(c.grid));
    }
}

TEST_F(BoothPassTest, DiffuseGridMatchesTheCpuModel)
{
    // The diffuse grid's nodes (mode 3) and the cache's interpolation (mode 0) against the
    // model's, on both flat scenes at the appliance's spacing and at 3 texels; on relief (eq. (1)
    // with each node's facet and horizons as well) the painting at 8 texels, which its rule never
    // picks but which the pass must draw as the model does, and the glossy cylinder at its own.
    const shading::View v = view(64, 40, 20.0);
    struct Case {
        const char* scene;
        int grid;
    };
    for (const Case c :
         {Case{"colorchecker", shading::kFlatDiffuseGrid},
          Case{"metamer", shading::kFlatDiffuseGrid}, Case{"metamer", 3},
          Case{"painting", shading::kFlatDiffuseGrid},
          Case{"glossy-cylinder", shading::defaultDiffuseGrid(scenes_.at("glossy-cylinder"))}}) {
        shading::RenderSettings settings;
        settings.diffuseGrid = c.grid;
        settings.specularGrid = shading::defaultSpecularGrid(scenes_.at(c.scene));
        expectMatchesTheCpuModel(scenes_.at(c.scene), settings, v,
                                 std::string(c.scene) + " diffuse grid " + std::to_string(c.grid));
    }
}

TEST_F(BoothPassTest, HorizonSpreadAndHalfFloatHorizonsMatchTheCpuModel)
{
    // Each light's horizon softness from its region's spread, the horizon sines as half floats
    // (eight a texel) and eq. (1)'s horizon read bilinearly at the pixel's point: the GL pass
    // against the CPU model on the painting at a 10-degree tilt, where the ceiling grazes the
    // panel and the horizons shadow most.
    const shading::View v = view(64, 40, 10.0);
    expectMatchesTheCpuModel(scenes_.at("painting"), paintingSettings(), v, "default horizons");
    // Direction counts that fill a layer partly (4 and 12 of 8 a layer) or span several (20).
    for (const int dirs : {4, 12, 20}) {
        shading::RenderSettings settings = paintingSettings();
        settings.horizonDirections = dirs;
        expectMatchesTheCpuModel(scenes_.at("painting"), settings, v,
                                 "half horizons, " + std::to_string(dirs) + " directions");
    }
}

TEST_F(BoothPassTest, HorizonPickMatchesTheCpuModel)
{
    // The two directions around a light's azimuth picked by comparisons, against the CPU model
    // on the painting at a 10-degree tilt, and where a direction count leaves one direction or
    // an odd number.
    for (const int dirs : {1, 3}) {
        shading::RenderSettings settings = paintingSettings();
        settings.horizonDirections = dirs;
        expectMatchesTheCpuModel(scenes_.at("painting"), settings, view(64, 40, 10.0),
                                 "picked from " + std::to_string(dirs) + " directions");
    }
}

TEST_F(BoothPassTest, BranchFreeSpecularSamplesMatchTheCpuModel)
{
    // The specular samples computed on every pixel and zeroed at the end where a test fails,
    // against the CPU model's early returns, on the glossy flat ColorChecker and the painting. From
    // the default eye the specular term lifts nearly every pixel (the kept samples must agree);
    // from a grazing eye and from above at a 10-degree tilt most samples fail a test (the zeros
    // must agree: dropping the "towards the ceiling" test fails the view from above).
    struct Case {
        shading::View view;
        bool specularShows;
    };
    std::vector<Case> cases{
            {view(64, 40, 30.0), true}, {view(64, 40, 30.0), false}, {view(64, 40, 10.0), false}};
    cases[1].view.eye = cases[1].view.panel.centre + 0.6 * cases[1].view.panel.right +
                        0.05 * cases[1].view.panel.normal;
    cases[2].view.eye = cases[2].view.panel.centre + 0.8 * cases[2].view.panel.up +
                        0.2 * cases[2].view.panel.normal;
    for (const char* name : {"colorchecker", "painting"}) {
        const auto& scene = scenes_.at(name);
        shading::RenderSettings base;
        base.specularSamples = shading::defaultSpecularSamples(scene);
        const auto ps = shading::prepareScene(scene, base.horizonDirections, 0.01, *basis_);
        const auto pl = shading::prepareLight(booth_->lights[2], *obs_, base.lights, *basis_);
        for (const Case& c : cases) {
            const shading::View& v = c.view;
            if (c.specularShows) {
                // The CPU model with and without the specular term, under d65-fluorescent.
                shading::RenderSettings matte = base;
                matte.specularPass = false;
                const auto with = shading::renderRealtime(ps, pl, v, *obs_, base);
                const auto without = shading::renderRealtime(ps, pl, v, *obs_, matte);
                std::size_t lifted = 0;
                for (std::size_t i = 0; i < with.xyz.size(); ++i) {
                    lifted += with.xyz[i].y > without.xyz[i].y * 1.001 + 1e-9 ? 1 : 0;
                }
                EXPECT_GT(lifted, with.xyz.size() * 9 / 10) << name;
            }
            expectMatchesTheCpuModel(scene, base, v, std::string(name) + ", branch-free");
        }
    }
}

TEST_F(BoothPassTest, ExactMipLevelMatchesTheCpuModel)
{
    // Each sample's nearest mip level from the footprint ratio's float exponent, against the CPU
    // model, whose level comes from log2 in double, at biases of whole half levels (the ratio
    // scaled by 4^bias). A quarter-level bias or trilinear levels the GL pass refuses (the CPU
    // model's alone, for the studies).
    const shading::View v = view(64, 40, 30.0);
    for (const char* name : {"colorchecker", "painting"}) {
        const auto& scene = scenes_.at(name);
        shading::RenderSettings settings;
        settings.specularSamples = shading::defaultSpecularSamples(scene);
        ASSERT_TRUE(settings.specularNearestLevel);
        for (const double bias : {0.0, 0.5, -1.0}) {
            settings.specularLodBias = bias;
            expectMatchesTheCpuModel(scene, settings, v,
                                     fmt::format("{}, exact level, bias {}", name, bias));
        }
        const auto ps = shading::prepareScene(scene, settings.horizonDirections, 0.01, *basis_);
        settings.specularLodBias = 0.25;
        auto quarter = BoothShadingPass::create(ps, settings, *obs_);
        ASSERT_FALSE(quarter);
        EXPECT_NE(quarter.error().message.find("bias of 0.25"), std::string::npos)
                << quarter.error().message;
        settings.specularLodBias = 0.0;
        settings.specularNearestLevel = false;
        auto trilinear = BoothShadingPass::create(ps, settings, *obs_);
        ASSERT_FALSE(trilinear);
        EXPECT_NE(trilinear.error().message.find("trilinear"), std::string::npos)
                << trilinear.error().message;
    }
}

// The tie tests' verdict on a GL frame against the CPU model's: the agreement
// expectMatchesTheCpuModel states.
void expectTieVerdict(const Agreement& a, const std::string& label)
{
    EXPECT_LE(a.fracOverTol, 0.002) << label << " max rel " << a.maxRelY;
    EXPECT_LE(a.de.max, 0.01) << label;
}

TEST_F(BoothPassTest, PixelCentresOnTexelEdgesTakeTheCpuModelsTexel)
{
    // At 48x30 and 96x60 a pixel row in about thirty has its centres exactly on a texel edge of
    // the painting. The GL pass's tie rule (the offset into the surface's pixels times the
    // texels, divided last) picks the CPU model's texel there; u * texels in float picked the
    // texel before on some of those rows, a whole pigment away at an edge.
    const auto& scene = scenes_.at("painting");
    shading::RenderSettings settings;
    settings.specularSamples = shading::defaultSpecularSamples(scene);
    const auto ps = shading::prepareScene(scene, settings.horizonDirections, 0.01, *basis_);
    const auto pl = shading::prepareLight(booth_->lights[2], *obs_, settings.lights, *basis_);
    for (const auto& [w, h] : {std::pair{48, 30}, std::pair{96, 60}}) {
        const shading::View v = view(w, h, 30.0);
        const auto cpu = shading::renderRealtime(ps, pl, v, *obs_, settings);
        auto pass = BoothShadingPass::create(ps, settings, *obs_);
        ASSERT_TRUE(pass) << pass.error().message;
        ASSERT_TRUE((*pass)->setLight(pl));
        const auto gl = renderBoothFrame(**pass, pl, v);
        ASSERT_TRUE(gl) << gl.error().message;
        expectTieVerdict(agree(cpu, *gl), fmt::format("{}x{}", w, h));
    }
}

TEST_F(BoothPassTest, AnOffsetLayoutTakesTheCpuModelsTexelsToo)
{
    // The appliance draws the surface into part of its frame (SurfaceLayout), and the tie rule
    // reads the surface's pixel rectangle from the layout. Here the surface fills pixels 12 to 108
    // across and 8 to 68 down of a 120x76 viewport: those pixels are the CPU model's 96x60 frame,
    // ties included.
    const auto& scene = scenes_.at("painting");
    shading::RenderSettings settings;
    settings.specularSamples = shading::defaultSpecularSamples(scene);
    const auto ps = shading::prepareScene(scene, settings.horizonDirections, 0.01, *basis_);
    const auto pl = shading::prepareLight(booth_->lights[2], *obs_, settings.lights, *basis_);
    const int w = 120, h = 76, x0 = 12, y0 = 8, pw = 96, ph = 60;
    SurfaceLayout layout;
    layout.scale = glm::dvec2(double(w) / pw, double(h) / ph);
    layout.offset = glm::dvec2(-layout.scale.x * x0 / w, -layout.scale.y * y0 / h);
    const shading::View cpuView = view(pw, ph, 30.0);
    const auto cpu = shading::renderRealtime(ps, pl, cpuView, *obs_, settings);
    auto pass = BoothShadingPass::create(ps, settings, *obs_);
    ASSERT_TRUE(pass) << pass.error().message;
    ASSERT_TRUE((*pass)->setLight(pl));
    auto target = XyzTarget::create(w, h);
    ASSERT_TRUE(target);
    (*target)->bind();
    const shading::View glView = view(w, h, 30.0);
    ASSERT_TRUE((*pass)->draw(glView, w, h, layout));
    const auto full = (*target)->read(pl, glView);
    shading::XyzFrame inner = cpu;
    for (int y = 0; y < ph; ++y) {
        for (int x = 0; x < pw; ++x) {
            inner.xyz[static_cast<std::size_t>(y * pw + x)] =
                    full.xyz[static_cast<std::size_t>((y0 + y) * w + x0 + x)];
        }
    }
    expectTieVerdict(agree(cpu, inner), "96x60 at (12, 8) in 120x76");
}

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

TEST_F(BoothPassTest, HardCasesNeverPutNaNOrInfInAPixel)
{
    // Relief shaded per pixel, and a flat surface on the appliance's grids (the specular term and
    // eq. (1) at grid nodes, interpolated).
    for (const bool bumpy : {true, false}) {
        auto scene = test::testScene(48, 32, bumpy, true);
        shading::RenderSettings settings;
        settings.lights = 16;
        settings.specularSamples = 8;
        settings.specularGrid = shading::defaultSpecularGrid(scene);
        settings.diffuseGrid = shading::defaultDiffuseGrid(scene);
        ASSERT_EQ(settings.diffuseGrid, bumpy ? 0 : shading::kFlatDiffuseGrid);
        expectHardCasesFinite(scene, settings);
    }
}

void BoothPassTest::expectHardCasesFinite(surface::SurfaceScene scene,
                                          const shading::RenderSettings& settings)
{
    for (double alpha : {0.0, 1e-6, 0.1, 2.0}) {
        scene.alpha = alpha;
        const auto ps = shading::prepareScene(scene, 8);
        auto pass = BoothShadingPass::create(ps, settings, *obs_);
        ASSERT_TRUE(pass) << pass.error().message;
        // A single hot texel, a zero image, and a light almost in the surface plane.
        auto hot = test::ceilingLight(32, 16, 0.0);
        hot.luminance.at(5, 7) = 1e7;
        auto dark = test::ceilingLight(32, 16, 0.0);
        auto low = test::ceilingLight(32, 16, 3000.0, 0.12);
        for (const auto* light : {&hot, &dark, &low}) {
            const auto pl = shading::prepareLight(*light, *obs_, settings.lights);
            ASSERT_TRUE((*pass)->setLight(pl));
            for (double tilt : {0.0, 30.0, 89.9, 90.0, 135.0}) {
                for (const shading::Vec3 eye :
                     {shading::Vec3(0.0, 0.45, 0.60), shading::Vec3(0.0, 0.2, -0.5)}) {
                    shading::View v = view(24, 16, tilt);
                    v.eye = eye;
                    auto gl = renderBoothFrame(**pass, pl, v);
                    ASSERT_TRUE(gl);
                    EXPECT_EQ(gl->nonFinite, 0) << "alpha " << alpha << " tilt " << tilt;
                    for (const auto& px : gl->xyz) {
                        ASSERT_GE(px.y, 0.0);
                        if (light == &dark) {
                            ASSERT_EQ(px.y, 0.0);
                        }
                    }
                }
            }
        }
    }
}

TEST_F(BoothPassTest, HardCasesOnShippedScenesMatchTheCpuModelAndTheReference)
{
    // The hard cases on every shipped scene, checked for accuracy rather than finiteness:
    // the booth's d65-fluorescent scaled to a 1 cd/m^2 and a 1e5 cd/m^2 peak, the panel tilted 80
    // to 89 degrees, eyes grazing the panel (2 degrees above its plane, from above and from the
    // side), and a lamp one texel wide. The appliance's setting for each scene (its specular
    // sample count, areas on flat scenes and points on relief), per pixel.
    // Stated tolerances, each against an independent value:
    //  - against the CPU model (double): expectMatchesTheCpuModel's, 1e-4 relative in Y on all but
    //    0.2 % of the pixels, dE00 <= 0.01 max and 0.001 mean;
    //  - linearity: the 1 cd/m^2 booth's frame times 1e5 is the 1e5 booth's to 1e-4 relative in Y
    //    (pixels over 1 % of the white): nothing in the pass has an absolute threshold;
    //  - against the exact reference (36 bands, every texel), half the budget or less:
    //    the booth light at every tilt and eye dE00 p95 <= 0.5 and max <= 2 (measured at most
    //    0.35 / 1.21, the painting seen grazing from the side; the flat scenes at 80-89 degrees
    //    0.012 / 0.013); the one-texel lamp on the matte metamer p95 <= 0.05 (measured 0.001); on
    //    glossy scenes the one-texel lamp's highlight is a stated limit (below).
    const booth::BoothLight& d65 = booth_->lights[2];
    // The appliance's basis, built for the light (every case has d65-fluorescent's spectrum): what
    // is left is the geometry's error, not the fixed basis's (the metamer's p95 1.5 under
    // replica_k6, docs/accuracy.md).
    auto encoder = spectral::AdaptiveEncoder::createDefault(dataDir());
    ASSERT_TRUE(encoder) << encoder.error().message;
    auto adaptive = encoder->basisFor(d65.spd);
    ASSERT_TRUE(adaptive) << adaptive.error().message;
    const colour::ChannelBasis& basis = *adaptive;
    const auto scaledTo = [&](double peak) {
        booth::BoothLight l = d65;
        const double m = l.luminance.max();
        for (double& t : l.luminance.cdM2) {
            t *= peak / m;
        }
        return l;
    };
    const booth::BoothLight dim = scaledTo(1.0);
    const booth::BoothLight bright = scaledTo(1e5);
    booth::BoothLight strip = d65; // one lit column in the middle of the lamp
    for (int y = 0; y < strip.luminance.height; ++y) {
        for (int x = 0; x < strip.luminance.width; ++x) {
            if (x != strip.luminance.width / 2) {
                strip.luminance.at(x, y) = 0.0;
            }
        }
    }
    struct Case {
        std::string what;
        shading::View view;
    };
    std::vector<Case> cases;
    for (const double tilt : {80.0, 85.0, 89.0}) {
        cases.push_back({fmt::format("tilt {}", tilt), view(24, 16, tilt)});
    }
    for (const bool side : {false, true}) {
        shading::View v = view(24, 16, 30.0);
        const double g = 2.0 * std::numbers::pi / 180.0;
        const shading::Vec3 along = side ? v.panel.right : v.panel.up;
        v.eye = v.panel.centre + 0.6 * (std::cos(g) * along + std::sin(g) * v.panel.normal);
        cases.push_back({side ? "grazing eye from the side" : "grazing eye from above", v});
    }
    double worstP95 = 0.0, worstMax = 0.0, worstStrip = 0.0, worstStripMatte = 0.0;
    for (const auto& [name, scene] : scenes_) {
        shading::RenderSettings settings;
        settings.specularSamples = shading::defaultSpecularSamples(scene);
        settings.areaLights = shading::defaultAreaLights(scene);
        if (name == "glossy-cylinder") {
            // Its plan's setting under d65-fluorescent, the light of these cases, and its grids:
            // what the appliance draws it with. The relief's fixed 8 samples are too few for its
            // sharp lobe (tilt 80: p95 1.04 at 8, 0.47 at 16, 0.15 at 48).
            settings.lights = 128;
            settings.specularSamples = 48;
            settings.specularGrid = shading::defaultSpecularGrid(scene);
            settings.diffuseGrid = shading::defaultDiffuseGrid(scene);
        }
        const auto ps = shading::prepareScene(scene, settings.horizonDirections, 0.01, basis);
        auto pass = BoothShadingPass::create(ps, settings, *obs_);
        ASSERT_TRUE(pass) << pass.error().message;
        const auto render = [&](const booth::BoothLight& light, const shading::View& v,
                                const std::string& label) {
            const auto pl = shading::prepareLight(light, *obs_, settings.lights, basis);
            EXPECT_TRUE((*pass)->setLight(pl));
            auto gl = renderBoothFrame(**pass, pl, v);
            EXPECT_TRUE(gl) << label;
            if (!gl) {
                return shading::XyzFrame{};
            }
            EXPECT_EQ(gl->nonFinite, 0) << label;
            const auto cpu = shading::renderRealtime(ps, pl, v, *obs_, settings);
            const Agreement a = agree(cpu, *gl);
            EXPECT_LE(a.fracOverTol, 0.002) << label << " max rel " << a.maxRelY;
            EXPECT_LE(a.de.max, 0.01) << label;
            EXPECT_LE(a.de.mean, 0.001) << label;
            return std::move(*gl);
        };
        for (const Case& c : cases) {
            const std::string label = name + ", " + c.what;
            const auto lo = render(dim, c.view, label + ", 1 cd/m^2");
            const auto hi = render(bright, c.view, label + ", 1e5 cd/m^2");
            ASSERT_EQ(lo.xyz.size(), hi.xyz.size());
            for (std::size_t i = 0; i < hi.xyz.size(); ++i) {
                if (hi.xyz[i].y > 0.01 * hi.whiteY) {
                    ASSERT_NEAR(lo.xyz[i].y * 1e5, hi.xyz[i].y, 1e-4 * hi.xyz[i].y)
                            << label << ", pixel " << i;
                }
            }
            const auto e = reference::compareFrames(
                    reference::renderReference(scene, bright, c.view, *obs_), hi);
            EXPECT_LE(e.p95, 0.5) << label;
            EXPECT_LE(e.max, 2.0) << label;
            worstP95 = std::max(worstP95, e.p95);
            worstMax = std::max(worstMax, e.max);
            std::printf("[ hard case ] %s: dE00 against the reference mean %.3f p95 %.3f max "
                        "%.3f\n",
                        label.c_str(), e.mean, e.p95, e.max);
        }
        for (const double tilt : {30.0, 85.0}) {
            const shading::View v = view(24, 16, tilt);
            const std::string label = fmt::format("{}, one-texel lamp, tilt {}", name, tilt);
            const auto gl = render(strip, v, label);
            const auto e = reference::compareFrames(
                    reference::renderReference(scene, strip, v, *obs_), gl);
            // Matte: the budget. Glossy: the specular samples find the strip's mirror image in the
            // mip chain, blurred over the level's texels, so the highlight is spread wrong
            // (measured p95 4.6 on the ColorChecker, 8.1 on the painting at 30 degrees, where
            // the strip's reflection is in view; 7.4 on the glossy cylinder, whose curved mirror
            // still shows it at 85 degrees, p95 2.1): a stated limit, held to 1.25 times that.
            const double limit = !scene.glossy()             ? 0.05
                                 : name == "painting"        ? 10.2
                                 : name == "glossy-cylinder" ? 9.2
                                                             : 5.8;
            EXPECT_LE(e.p95, limit) << label;
            (scene.glossy() ? worstStrip : worstStripMatte) =
                    std::max(scene.glossy() ? worstStrip : worstStripMatte, e.p95);
            std::printf("[ hard case ] %s: dE00 against the reference mean %.3f p95 %.3f max "
                        "%.3f\n",
                        label.c_str(), e.mean, e.p95, e.max);
        }
    }
    RecordProperty("worst_p95", std::to_string(worstP95));
    RecordProperty("worst_max", std::to_string(worstMax));
    RecordProperty("worst_strip_p95_glossy", std::to_string(worstStrip));
    RecordProperty("worst_strip_p95_matte", std::to_string(worstStripMatte));
}

TEST_F(BoothPassTest, PanelLayoutShowsTheSurfaceAtPhysicalSizeAndBlackAround)
{
    const auto& scene = scenes_.at("colorchecker");
    const shading::RenderSettings settings;
    const auto ps = shading::prepareScene(scene, 8, 0.01, *basis_);
    auto pass = BoothShadingPass::create(ps, settings, *obs_);
    ASSERT_TRUE(pass);
    const auto pl = shading::prepareLight(booth_->lights[0], *obs_, 32, *basis_);
    ASSERT_TRUE((*pass)->setLight(pl));
    const scene::StandModel stand;
    const SurfaceLayout layout = layoutOnPanel(scene, stand);
    EXPECT_NEAR(layout.scale.x, stand.panelWidthM / scene.widthM, 1e-12);
    const int w = 104, h = 65; // 5 mm pixels on the 0.518 x 0.324 m panel
    auto target = XyzTarget::create(w, h);
    ASSERT_TRUE(target);
    (*target)->bind();
    shading::View v = view(w, h);
    ASSERT_TRUE((*pass)->draw(v, w, h, layout));
    const auto f = (*target)->read(pl, v);
    // Lit columns: the surface's width in pixels, centred.
    int lit = 0;
    for (int x = 0; x < w; ++x) {
        lit += f.xyz[static_cast<std::size_t>(h / 2) * w + x].y > 0.0 ? 1 : 0;
    }
    EXPECT_NEAR(lit, scene.widthM / stand.panelWidthM * w, 1.5);
    EXPECT_EQ(f.xyz[0].y, 0.0);
    EXPECT_GT(f.xyz[static_cast<std::size_t>(h / 2) * w + w / 2].y, 0.0);
}

} // namespace
} // namespace replica::pipeline::render
