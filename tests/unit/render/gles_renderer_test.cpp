// The GLES renderer against closed-form values computed on the CPU, on the real headless EGL path.
#include <cmath>
#include <numbers>

#include <glm/geometric.hpp>

#include <pipeline/base/data_dir.h>
#include <pipeline/display/display_inverse.h>
#include <pipeline/display/nominal_display.h>
#include <pipeline/render/gles_renderer.h>

#include <gtest/gtest.h>

#include "../support/headless_gl.h"

namespace replica::pipeline::render {
namespace {

class GlesRendererTest : public tests::HeadlessGlTest
{
protected:
    std::unique_ptr<Renderer> make(double reflectance, int lightsU, int lightsV)
    {
        GlesRendererSetup s = tests::flatRendererSetup();
        s.surface.width = 2;
        s.surface.height = 2;
        s.surface.coeffs.assign(2 * 2 * colour::kChannels, static_cast<float>(reflectance));
        s.display.model = display::nominalDisplayModel("srgb-like-800", 800.0, 0.4);
        s.display.viewingCompensation = false; // the CPU reference below is on-axis, flare-free
        s.display.flareSubtraction = false;
        s.lightsU = lightsU;
        s.lightsV = lightsV;
        setup_ = s;
        auto r = createGlesRenderer(s);
        EXPECT_TRUE(r) << r.error().message;
        return r ? std::move(*r) : nullptr;
    }

    // Paper eq. (1) in double for the pixel centre (x, y).
    double illuminance(const scene::SceneState& st, int x, int y) const
    {
        const auto pose = scene::panelPose(setup_.stand, st.tiltRad);
        const double u = (x + 0.5) / setup_.width;
        const double v = (y + 0.5) / setup_.height;
        const glm::dvec3 p = pose.cornerM() + u * pose.rightEdgeM() + v * pose.upEdgeM();
        return tests::gridIlluminance(setup_.booth, st.emitterLuminanceCdM2, setup_.lightsU,
                                      setup_.lightsV, pose, p);
    }

    scene::SceneState state(double tilt) const
    {
        scene::SceneState st;
        st.illuminant = setup_.booth.lights[0].referenceSpectrum;
        st.emitterLuminanceCdM2 = 2000.0;
        st.tiltRad = tilt;
        return st;
    }

    GlesRendererSetup setup_;
};

TEST_F(GlesRendererTest, DiffuseLuminanceMatchesThePointLightFormula)
{
    auto r = make(0.5, 4, 2);
    ASSERT_TRUE(r);
    for (double tilt : {0.0, 0.35, 0.7}) {
        const auto st = state(tilt);
        RenderedFrame f;
        ASSERT_TRUE(r->render(st, f));
        ASSERT_EQ(f.width, 64);
        for (auto [x, y] :
             {std::pair{0, 0}, std::pair{31, 20}, std::pair{63, 39}, std::pair{10, 33}}) {
            const double expectedY = 0.5 * illuminance(st, x, y) / std::numbers::pi;
            const float gotY =
                    f.xyz[(static_cast<std::size_t>(y) * 64 + static_cast<std::size_t>(x)) * 4 + 1];
            ASSERT_GT(expectedY, 1.0);
            EXPECT_NEAR(gotY / expectedY, 1.0, 2e-5)
                    << "tilt " << tilt << " pixel " << x << "," << y;
        }
    }
}

TEST_F(GlesRendererTest, LightBehindTheScreenGivesExactlyZeroAndNoNaN)
{
    auto r = make(0.9, 8, 4);
    ASSERT_TRUE(r);
    // Tilted 100 degrees forward the screen faces the floor: the ceiling light is behind it.
    RenderedFrame f;
    ASSERT_TRUE(r->render(state(-1.75), f));
    for (float v : f.xyz) {
        ASSERT_TRUE(std::isfinite(v));
    }
    for (std::size_t i = 0; i < f.xyz.size(); i += 4) {
        ASSERT_EQ(f.xyz[i + 1], 0.0f);
    }
}

TEST_F(GlesRendererTest, SameInputsGiveBitIdenticalFrames)
{
    auto r = make(0.3, 8, 4);
    ASSERT_TRUE(r);
    RenderedFrame a;
    RenderedFrame b;
    ASSERT_TRUE(r->render(state(0.2), a));
    ASSERT_TRUE(r->render(state(0.5), b)); // something different in between
    ASSERT_TRUE(r->render(state(0.2), b));
    EXPECT_EQ(a.xyz, b.xyz);
    EXPECT_EQ(a.rgba, b.rgba);
}

TEST_F(GlesRendererTest, DisplayPassMatchesTheCpuInverseWithinOneCount)
{
    auto r = make(0.4, 8, 4);
    ASSERT_TRUE(r);
    RenderedFrame f;
    ASSERT_TRUE(r->render(state(0.35), f));
    auto inverse = display::DisplayInverse::build(setup_.display.model);
    ASSERT_TRUE(inverse);
    for (std::size_t px = 0; px < static_cast<std::size_t>(f.width * f.height); px += 97) {
        const glm::dvec3 xyz{f.xyz[px * 4], f.xyz[px * 4 + 1], f.xyz[px * 4 + 2]};
        const auto counts = inverse->invert(xyz).counts;
        for (int c = 0; c < 3; ++c) {
            EXPECT_NEAR(f.rgba[px * 4 + static_cast<std::size_t>(c)], counts[c], 1.0);
        }
    }
}

} // namespace
} // namespace replica::pipeline::render
