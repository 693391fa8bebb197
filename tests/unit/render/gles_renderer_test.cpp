// The GLES renderer (the booth pass, then the display pass) on the real headless EGL path: the same
// inputs give the same frame, pass 2 drives what the CPU inverse says for pass 1's XYZ, and a
// set-up without its pass 1 is refused.
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
    std::unique_ptr<Renderer> make()
    {
        GlesRendererSetup s = tests::rendererSetup("colorchecker");
        s.display.model = display::nominalDisplayModel("srgb-like-800", 800.0, 0.4);
        s.display.viewingCompensation = false; // the CPU reference below is on-axis, flare-free
        s.display.flareSubtraction = false;
        setup_ = s;
        auto r = createGlesRenderer(s);
        EXPECT_TRUE(r) << r.error().message;
        return r ? std::move(*r) : nullptr;
    }

    static scene::SceneState state(double tilt)
    {
        scene::SceneState st;
        st.lampIndex = 1;
        st.tiltRad = tilt;
        return st;
    }

    GlesRendererSetup setup_;
};

TEST_F(GlesRendererTest, SameInputsGiveBitIdenticalFrames)
{
    auto r = make();
    ASSERT_TRUE(r);
    RenderedFrame a;
    RenderedFrame b;
    ASSERT_TRUE(r->render(state(0.2), a, Readback::DisplayAndXyz));
    ASSERT_TRUE(r->render(state(0.5), b, Readback::DisplayAndXyz)); // something different between
    EXPECT_NE(a.xyz, b.xyz);
    ASSERT_TRUE(r->render(state(0.2), b, Readback::DisplayAndXyz));
    EXPECT_EQ(a.xyz, b.xyz);
    EXPECT_EQ(a.rgba, b.rgba);
}

TEST_F(GlesRendererTest, DisplayPassMatchesTheCpuInverseWithinOneCount)
{
    auto r = make();
    ASSERT_TRUE(r);
    RenderedFrame f;
    ASSERT_TRUE(r->render(state(0.35), f, Readback::DisplayAndXyz));
    ASSERT_EQ(f.width, 64);
    auto inverse = display::DisplayInverse::build(setup_.display.model);
    ASSERT_TRUE(inverse);
    int lit = 0;
    for (std::size_t px = 0; px < static_cast<std::size_t>(f.width * f.height); px += 7) {
        const glm::dvec3 xyz{f.xyz[px * 4], f.xyz[px * 4 + 1], f.xyz[px * 4 + 2]};
        lit += xyz.y > 1.0 ? 1 : 0;
        const auto counts = inverse->invert(xyz).counts;
        for (int c = 0; c < 3; ++c) {
            EXPECT_NEAR(f.rgba[px * 4 + static_cast<std::size_t>(c)], counts[c], 1.0) << px;
        }
    }
    EXPECT_GT(lit, 50) << "too few lit pixels: the test cannot tell";
}

TEST_F(GlesRendererTest, RefusesASetupWithoutItsPass1)
{
    GlesRendererSetup s;
    s.display.model = display::nominalDisplayModel("srgb-like-800", 800.0, 0.4);
    auto r = createGlesRenderer(s);
    ASSERT_FALSE(r);
    EXPECT_NE(r.error().message.find("booth scene pass"), std::string::npos) << r.error().message;
}

} // namespace
} // namespace replica::pipeline::render
