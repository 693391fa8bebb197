// The booth dimmer: the automatic scale against closed forms, its effect on what the display can
// show, the site key, the recorded setting (absent: 1) and its effect on the rendered frame.
#include <cmath>
#include <filesystem>
#include <fstream>

#include <nlohmann/json.hpp>

#include <pipeline/display/nominal_display.h>
#include <platform/appliance.h>
#include <platform/booth_dimmer.h>
#include <platform/site_config.h>

#include <gtest/gtest.h>

namespace replica::platform {
namespace {
namespace fs = std::filesystem;

pipeline::shading::XyzFrame greyRamp(int n, double maxY)
{
    // Neutral greys (the D65 chromaticity) Y = maxY * (i + 1) / n: the quantile is known.
    pipeline::shading::XyzFrame f;
    f.width = n;
    f.height = 1;
    const glm::dvec3 d65{0.95047, 1.0, 1.08883};
    for (int i = 0; i < n; ++i) {
        f.xyz.push_back(d65 * (maxY * (i + 1) / n));
    }
    f.whiteXyz = d65 * maxY;
    f.whiteY = maxY;
    return f;
}

TEST(BoothDimmer, AutoBringsTheQuantileToThePeak)
{
    // Y = 10, 20, ..., 1000 (101 values with 0 at the bottom would move the rank): the 99th
    // percentile of 100 values at rank 0.99 * 99 = 98.01 is 990 + 0.01 * 10 = 990.1.
    const auto f = greyRamp(100, 1000.0);
    EXPECT_NEAR(autoBoothDimmer({f}, 900.0), 900.0 / 990.1, 1e-12);
    EXPECT_NEAR(autoBoothDimmer({f}, 500.0, 0.5), 500.0 / 505.0, 1e-12); // rank 49.5
    // A scene that fits is left alone; no peak or a dark scene: 1.
    EXPECT_EQ(autoBoothDimmer({f}, 2000.0), 1.0);
    EXPECT_EQ(autoBoothDimmer({f}, 0.0), 1.0);
    EXPECT_EQ(autoBoothDimmer({greyRamp(10, 0.0)}, 900.0), 1.0);
    // Over several frames (one per lamp) the pixels are pooled.
    EXPECT_NEAR(autoBoothDimmer({greyRamp(100, 500.0), f}, 900.0, 1.0), 0.9, 1e-12);
}

TEST(BoothDimmer, EffectCountsWhatTheDisplayCannotShow)
{
    const auto model = pipeline::display::nominalDisplayModel("test-900", 900.0, 0.0);
    auto inverse = pipeline::display::DisplayInverse::build(model);
    ASSERT_TRUE(inverse) << inverse.error().message;
    // Greys up to twice the peak: half of them (Y > 900 of 18, 36, ..., 1800) are over it.
    const auto f = greyRamp(100, 1800.0);
    const DimmerEffect undimmed = boothDimmerEffect(f, 1.0, *inverse);
    EXPECT_NEAR(undimmed.overPeakFraction, 0.5, 0.011);
    EXPECT_GT(undimmed.de00Max, 5.0); // the top greys all show at the peak
    // Dimmed to fit (the white at 0.5 * 1800 = 900): nothing over the peak, and with a black of
    // 0 the greys show as they are (the white point is D65 on the nominal panel) to the tone
    // table's interpolation.
    const DimmerEffect dimmed = boothDimmerEffect(f, 0.5, *inverse);
    EXPECT_EQ(dimmed.overPeakFraction, 0.0);
    EXPECT_LT(dimmed.de00Max, 0.05);
}

TEST(BoothDimmer, DemandDividesByTheViewingGainAtEachPixel)
{
    // A panel whose white keeps 0.5 of its luminance at 60 degrees (no colour shift): a pixel
    // seen from 60 degrees off the normal asks for twice its Y, one seen on the normal for its Y.
    auto model = pipeline::display::nominalDisplayModel("test-900", 900.0, 0.0);
    model.viewing.angleDeg = {0.0, 60.0};
    model.viewing.luminanceRatio = {1.0, 0.5};
    model.viewing.dx = {0.0, 0.0};
    model.viewing.dy = {0.0, 0.0};
    DimmerView v;
    v.frame = greyRamp(2, 600.0); // Y = 300, 600
    v.pixelM = {{0.0, 0.0, 0.0}, {1.0, 0.0, 0.0}};
    v.normal = {0.0, 0.0, 1.0};
    // The eye on the first pixel's normal, and 60 degrees off the second's: tan 60 = 1 / z.
    v.eyeM = {0.0, 0.0, 1.0 / std::sqrt(3.0)};
    const auto d = panelDemand(v, model, true);
    ASSERT_EQ(d.xyz.size(), 2u);
    EXPECT_NEAR(d.xyz[0].y, 300.0, 1e-9);
    EXPECT_NEAR(d.xyz[1].y, 1200.0, 1e-6);
    // Compensation off: the frame as it is. Above the 900 peak: the second pixel only, until a
    // scale brings 1200 under it.
    EXPECT_NEAR(panelDemand(v, model, false).xyz[1].y, 600.0, 1e-12);
    EXPECT_EQ(overPeakFraction(d, 1.0, 900.0), 0.5);
    EXPECT_EQ(overPeakFraction(d, 0.74, 900.0), 0.0);
    EXPECT_EQ(overPeakFraction(d, 0.76, 900.0), 0.5);
}

TEST(BoothDimmer, SiteKeyTakesANumberOrAuto)
{
    const fs::path dir = fs::temp_directory_path() / ("dimmer-" + std::to_string(::getpid()));
    fs::create_directories(dir);
    const auto load = [&](const std::string& text) {
        std::ofstream(dir / "replica.toml") << text;
        return loadSiteConfig(dir / "replica.toml");
    };
    auto a = load("[booth]\ndimmer = 0.25\n");
    ASSERT_TRUE(a);
    EXPECT_TRUE(a->problems.empty());
    EXPECT_EQ(a->config.boothDimmer, 0.25);
    EXPECT_FALSE(a->config.boothDimmerAuto);
    auto b = load("[booth]\ndimmer = \"auto\"\n");
    ASSERT_TRUE(b);
    EXPECT_TRUE(b->problems.empty());
    EXPECT_TRUE(b->config.boothDimmerAuto);
    EXPECT_EQ(nlohmann::json::parse(b->config.toJson())["booth"]["dimmer"], "auto");
    for (const char* bad : {"[booth]\ndimmer = 0\n", "[booth]\ndimmer = 1.5\n",
                            "[booth]\ndimmer = \"half\"\n", "[booth]\ndimmer = true\n"}) {
        auto c = load(bad);
        ASSERT_TRUE(c);
        ASSERT_EQ(c->problems.size(), 1u) << bad;
        EXPECT_EQ(c->problems[0].key, "booth.dimmer");
        EXPECT_EQ(c->problems[0].line, 2);
        EXPECT_EQ(c->config.boothDimmer, 1.0);
    }
    fs::remove_all(dir);
}

TEST(BoothDimmer, RecordedSettingIsOneWhenAbsentAndRoundTrips)
{
    RunConfig c;
    c.boothDimmer = 0.4;
    c.boothDimmerChosenAuto = true;
    auto back = RunConfig::fromJson(c.toJson());
    ASSERT_TRUE(back) << back.error().message;
    EXPECT_EQ(back->boothDimmer, 0.4);
    EXPECT_TRUE(back->boothDimmerChosenAuto);
    EXPECT_FALSE(back->boothDimmerAuto); // a replay never chooses again
    auto j = nlohmann::json::parse(c.toJson());
    j.erase("booth_dimmer");
    j.erase("booth_dimmer_auto");
    auto old = RunConfig::fromJson(j.dump());
    ASSERT_TRUE(old) << old.error().message;
    EXPECT_EQ(old->boothDimmer, 1.0);
    for (const double bad : {0.0, -0.5, 1.5}) {
        j["booth_dimmer"] = bad;
        EXPECT_FALSE(RunConfig::fromJson(j.dump())) << bad;
    }
}

TEST(BoothDimmer, ScalesTheRenderedFrameAndAutoFitsThePanel)
{
    // The flat metamer scene (no specular, no relief): pass 1's XYZ is linear in the light, so
    // a dimmer of 0.5 halves every pixel to float rounding.
    RunConfig base;
    base.width = 64;
    base.height = 40;
    base.sceneDir = "scenes/metamer";
    pipeline::scene::SceneState state;
    state.tiltRad = 0.35;
    const auto render = [&](const RunConfig& c, RunConfig* resolved = nullptr) {
        auto app = buildAppliance(c);
        EXPECT_TRUE(app) << (app ? "" : app.error().message);
        pipeline::render::RenderedFrame f;
        if (!app) {
            return f;
        }
        state.lampIndex = 2;
        state.illuminant = (*app)->booth.lights[2].referenceSpectrum;
        state.emitterLuminanceCdM2 = (*app)->booth.lights[2].nominalLuminanceCdM2;
        EXPECT_TRUE((*app)->renderer->render(state, f, pipeline::render::Readback::DisplayAndXyz));
        if (resolved != nullptr) {
            *resolved = (*app)->config;
        }
        return f;
    };
    const auto full = render(base);
    // The gamut counts: the surface's rectangle counted on its own, the black surround (below
    // black by construction) the rest of the frame.
    const auto& g = full.gamut;
    EXPECT_EQ(g.pixels, 64u * 40u);
    EXPECT_GT(g.surfacePixels, 0u);
    EXPECT_LT(g.surfacePixels, g.pixels);
    EXPECT_EQ(g.belowBlack - g.surfaceBelowBlack, g.pixels - g.surfacePixels);
    EXPECT_EQ(g.chroma, g.surfaceChroma);
    EXPECT_EQ(g.overPeak, g.surfaceOverPeak);
    EXPECT_GE(g.outOfGamutFraction(), g.surfaceOutOfGamutFraction() *
                                              static_cast<double>(g.surfacePixels) /
                                              static_cast<double>(g.pixels));
    RunConfig half = base;
    half.boothDimmer = 0.5;
    const auto dimmed = render(half);
    ASSERT_EQ(full.xyz.size(), dimmed.xyz.size());
    ASSERT_FALSE(full.xyz.empty());
    int lit = 0;
    for (std::size_t i = 1; i < full.xyz.size(); i += 4) { // Y of each RGBA pixel
        if (full.xyz[i] > 1.0f) {
            ++lit;
            ASSERT_NEAR(dimmed.xyz[i], 0.5f * full.xyz[i], 1e-5f * full.xyz[i]) << i;
        }
    }
    EXPECT_GT(lit, 100);
    // Auto: the number chosen is recorded, in (0, 1], and no more than the peak over the
    // surface's 99th percentile asks.
    RunConfig autoCfg = base;
    autoCfg.boothDimmerAuto = true;
    RunConfig resolved;
    (void)render(autoCfg, &resolved);
    EXPECT_FALSE(resolved.boothDimmerAuto);
    EXPECT_TRUE(resolved.boothDimmerChosenAuto);
    EXPECT_GT(resolved.boothDimmer, 0.0);
    EXPECT_LE(resolved.boothDimmer, 1.0);
}

} // namespace
} // namespace replica::platform
