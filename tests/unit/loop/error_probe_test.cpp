// The running appliance's error probe: its pixels lie on the surface and repeat with the seed, its
// ΔE00 is ~0 where the frame is the exact reference and catches a planted error, the pixels it
// reads back are the frame's, and its record round-trips through a recording.
#include <algorithm>
#include <cstdio>

#include <pipeline/reference/reference_integrator.h>
#include <pipeline/render/surface_layout.h>
#include <platform/appliance.h>
#include <platform/loop/error_probe.h>

#include <gtest/gtest.h>

#include "../render/render_fixtures.h"

namespace replica::platform {
namespace {

namespace render = pipeline::render;

// A frame of the exact reference (renderReference: rows top-down, the whole surface) as the GL
// pass would hand it over (rows bottom-up, 4 floats a pixel), at 'pixels'.
std::vector<float> framePixels(const pipeline::shading::XyzFrame& f,
                               const std::vector<render::FramePixel>& pixels,
                               double scale)
{
    std::vector<float> out;
    for (const auto& p : pixels) {
        const auto& c = f.xyz[static_cast<std::size_t>(f.height - 1 - p.y) * f.width + p.x];
        for (const double v : {c.x, c.y, c.z, 1.0}) {
            out.push_back(static_cast<float>(v * scale));
        }
    }
    return out;
}

struct ReferenceCase {
    pipeline::surface::SurfaceScene scene = test::testScene(24, 16, true, true);
    pipeline::booth::Booth booth;
    pipeline::scene::SceneState state;
    ProbeScene probe;
    pipeline::shading::XyzFrame frame;
    ReferenceCase()
    {
        booth.lights.push_back(test::stripedLight(24, 12));
        state.lampIndex = 0;
        state.tiltRad = 0.2;
        state.eyeBoothM = {0.05, 0.45, 0.55};
        probe.scene = &scene;
        probe.booth = &booth;
        probe.observer = &test::observer();
        probe.layout = {}; // the frame covers the surface, as renderReference's view does
        pipeline::shading::View view;
        view.panel = pipeline::scene::panelPose(probe.stand, state.tiltRad);
        view.eye = state.eyeBoothM;
        view.pixelsX = 48;
        view.pixelsY = 32;
        frame = pipeline::reference::renderReference(scene, booth.lights[0], view,
                                                     test::observer());
    }
};

TEST(ErrorProbe, PixelsLieOnTheSurfaceAndRepeatWithTheSeed)
{
    auto scene = test::testScene(40, 20, false, false);
    pipeline::scene::StandModel stand;
    const auto layout = render::layoutOnPanel(scene, stand);
    ASSERT_GT(layout.scale.x, 1.0); // the surface is smaller than the panel: a black surround
    const auto a = probePixels(layout, 160, 100, 300, 7);
    ASSERT_EQ(a.size(), 300u);
    const double x0 = -layout.offset.x / layout.scale.x * 160;
    const double x1 = (1.0 - layout.offset.x) / layout.scale.x * 160;
    for (const auto& p : a) {
        EXPECT_GE(p.x + 0.5, x0);
        EXPECT_LE(p.x + 0.5, x1);
    }
    const auto b = probePixels(layout, 160, 100, 300, 7);
    const auto c = probePixels(layout, 160, 100, 300, 8);
    const auto same = [](const auto& u, const auto& v) {
        return std::equal(u.begin(), u.end(), v.begin(), v.end(),
                          [](const auto& p, const auto& q) { return p.x == q.x && p.y == q.y; });
    };
    EXPECT_TRUE(same(a, b));
    EXPECT_FALSE(same(a, c));
}

TEST(ErrorProbe, TheReferenceAgainstItselfIsZeroAndAPlantedErrorIsCaught)
{
    const ReferenceCase c;
    const auto pixels = probePixels(c.probe.layout, 48, 32, 120, 3);
    ASSERT_EQ(pixels.size(), 120u);
    const auto same =
            measureError(c.probe, c.state, 48, 32, pixels, framePixels(c.frame, pixels, 1.0));
    ASSERT_TRUE(same);
    EXPECT_EQ(same->n, 120u);
    EXPECT_LT(same->p95, 1e-3); // float rounding of the frame only
    EXPECT_LT(same->max, 1e-2);
    // 10 % too bright everywhere: well over the budget of 1.
    const auto bright =
            measureError(c.probe, c.state, 48, 32, pixels, framePixels(c.frame, pixels, 1.1));
    ASSERT_TRUE(bright);
    EXPECT_GT(bright->p95, 1.5);
    EXPECT_GT(bright->mean, 1.0);
    // Another state (the panel tilted further) is not this frame's reference: the probe sees the
    // difference.
    auto moved = c.state;
    moved.tiltRad = 0.6;
    const auto other =
            measureError(c.probe, moved, 48, 32, pixels, framePixels(c.frame, pixels, 1.0));
    ASSERT_TRUE(other);
    EXPECT_GT(other->max, 1.0);
    // Stopped (the run ended): no result rather than one over fewer pixels.
    int asked = 0;
    EXPECT_FALSE(measureError(c.probe, c.state, 48, 32, pixels, framePixels(c.frame, pixels, 1.0),
                              [&asked] { return ++asked > 10; }));
    EXPECT_EQ(asked, 11);
}

TEST(ErrorProbe, ReadsTheFramesPixelsAndMeasuresTheApplianceFrame)
{
    RunConfig config;
    config.width = 96;
    config.height = 60;
    config.sceneDir = "scenes/metamer";
    auto app = buildAppliance(config);
    ASSERT_TRUE(app) << app.error().message;
    pipeline::scene::SceneState state;
    state.lampIndex = 2;
    state.tiltRad = 0.3;
    state.illuminant = (*app)->booth.lights[2].referenceSpectrum;
    state.emitterLuminanceCdM2 = (*app)->booth.lights[2].nominalLuminanceCdM2;
    render::RenderedFrame f;
    ASSERT_TRUE((*app)->renderer->render(state, f, render::Readback::DisplayAndXyz));
    const ProbeScene ps = probeScene((*app)->boothScene->setup());
    const auto pixels = probePixels(ps.layout, 96, 60, 150, 11);
    std::vector<float> xyz;
    ASSERT_TRUE((*app)->renderer->readXyzPixels(pixels, xyz));
    ASSERT_EQ(xyz.size(), 4 * pixels.size());
    for (std::size_t k = 0; k < pixels.size(); ++k) {
        const auto at = 4 * (static_cast<std::size_t>(pixels[k].y) * 96 + pixels[k].x);
        for (std::size_t i = 0; i < 4; ++i) {
            ASSERT_EQ(xyz[4 * k + i], f.xyz[at + i]) << k;
        }
    }
    const auto e = measureError(ps, state, 96, 60, pixels, xyz);
    ASSERT_TRUE(e);
    // The frame's own error (this state draws with the fixed general basis, encoding 0: a few
    // metamer patches are off by about 1.5), small on most pixels where the probe's pixel ->
    // surface mapping is the pass's; the same pixels read upside down land on other patches.
    std::vector<render::FramePixel> flipped;
    for (const auto& p : pixels) {
        flipped.push_back({p.x, 59 - p.y});
    }
    std::vector<float> upsideDown;
    ASSERT_TRUE((*app)->renderer->readXyzPixels(flipped, upsideDown));
    const auto wrong = measureError(ps, state, 96, 60, pixels, upsideDown);
    ASSERT_TRUE(wrong);
    std::printf("metamer 96x60, lamp 2: p95 %.3f max %.3f mean %.3f; rows flipped: mean %.3f\n",
                e->p95, e->max, e->mean, wrong->mean);
    EXPECT_LT(e->mean, 0.5);
    EXPECT_LT(e->p95, 2.0);
    EXPECT_GT(wrong->mean, 4.0 * e->mean);
    for (auto& v : xyz) {
        v *= 1.1f;
    }
    const auto bright = measureError(ps, state, 96, 60, pixels, xyz);
    ASSERT_TRUE(bright);
    EXPECT_GT(bright->p95, e->p95 + 0.5);
    // Outside the frame: refused, not read.
    EXPECT_FALSE((*app)->renderer->readXyzPixels({{96, 0}}, xyz));
}

} // namespace
} // namespace replica::platform
