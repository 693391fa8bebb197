// The GLES booth pass on the real headless EGL path against the CPU model it follows
// (shading::renderRealtime): every shipped scene and light, the grids, the horizon and specular
// variants, the texel rules and the panel layout.
#include "booth_pass_fixture.h"

namespace replica::pipeline::render {
namespace {

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
