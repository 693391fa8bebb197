// The GLES booth pass on the hard cases (docs/rendering.md): no NaN or Inf in any pixel, and on
// the shipped scenes the GL frame stays with the CPU model and the exact reference.
#include "booth_pass_fixture.h"

namespace replica::pipeline::render {

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

namespace {

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

} // namespace
} // namespace replica::pipeline::render
