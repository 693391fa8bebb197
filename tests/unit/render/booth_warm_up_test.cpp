// BoothScenePass::warmUp: drawing every lamp's shading pass once at start changes no frame the loop
// draws afterwards (bit for bit, across lamp switches between passes of different settings) and
// no count the loop reports.
#include <pipeline/render/booth_scene_pass.h>
#include <pipeline/render/xyz_target.h>
#include <pipeline/scene/booth.h>

#include <gtest/gtest.h>

#include "../support/headless_gl.h"

namespace replica::pipeline::render {
namespace {

constexpr int kWarmW = 48, kWarmH = 30;

class BoothWarmUpTest : public tests::HeadlessGlTest
{
protected:
    void SetUp() override
    {
        tests::HeadlessGlTest::SetUp();
        if (IsSkipped()) {
            return;
        }
        setup_ = tests::boothPassSetup("colorchecker"); // glossy
        setup_.settings.specularSamples = 8;
        setup_.settings.subtractFlare = false;
        // Three passes: the setup's (walls and a specular term; tungsten draws it), and one of its
        // own for each fluorescent: d50 without the walls, d65 without the specular term. (Counts
        // alone do not make a pass: BoothLampShareTest.)
        setup_.booth.walls = scene::defaultBoothWalls(setup_.booth.ceiling());
        setup_.perLamp["d50-fluorescent"] = LampSettings{8, 24, 0, false};
        setup_.perLamp["d65-fluorescent"] = LampSettings{32, 0, 0, true};
        auto t = XyzTarget::create(kWarmW, kWarmH);
        ASSERT_TRUE(t);
        target_ = std::move(*t);
    }

    // Lamp 0, 1, 2, 0, 2 with the eye and the tilt moving: every frame's floats, alpha too.
    std::vector<std::vector<float>> run(BoothScenePass& pass)
    {
        std::vector<std::vector<float>> frames;
        const int lamps[] = {0, 0, 1, 1, 2, 2, 0, 2};
        for (int i = 0; i < 8; ++i) {
            scene::SceneState st;
            st.lampIndex = lamps[i];
            st.tiltRad = 0.30 + 0.02 * i;
            st.eyeBoothM = {-0.2 + 0.05 * i, 0.45, 0.60};
            target_->bind();
            auto ok = pass.draw(st, kWarmW, kWarmH);
            EXPECT_TRUE(ok) << (ok ? "" : ok.error().message);
            frames.push_back(tests::readFloats(*target_));
        }
        return frames;
    }

    std::unique_ptr<XyzTarget> target_;
    BoothSceneSetup setup_;
};

TEST_F(BoothWarmUpTest, ChangesNoFrameAndNoCount)
{
    auto cold = BoothScenePass::create(setup_);
    auto warm = BoothScenePass::create(setup_);
    ASSERT_TRUE(cold && warm);
    ASSERT_EQ((*warm)->variantCount(), 3u);
    // Warmed up into its own target, with a different viewport bound before: both come back.
    target_->bind();
    glViewport(1, 2, 7, 5);
    auto ms = (*warm)->warmUp(20, 12); // another size than the frames: the cache follows
    ASSERT_TRUE(ms) << ms.error().message;
    EXPECT_GT(*ms, 0.0);
    GLint fb = 0;
    GLint vp[4] = {0, 0, 0, 0};
    glGetIntegerv(GL_DRAW_FRAMEBUFFER_BINDING, &fb);
    glGetIntegerv(GL_VIEWPORT, vp);
    GLint want = 0;
    target_->bind();
    glGetIntegerv(GL_DRAW_FRAMEBUFFER_BINDING, &want);
    EXPECT_EQ(fb, want);
    EXPECT_EQ(vp[0], 1);
    EXPECT_EQ(vp[1], 2);
    EXPECT_EQ(vp[2], 7);
    EXPECT_EQ(vp[3], 5);
    EXPECT_EQ((*warm)->cacheRefreshes(), 0);

    const auto a = run(**cold);
    const auto b = run(**warm);
    ASSERT_EQ(a.size(), b.size());
    for (std::size_t f = 0; f < a.size(); ++f) {
        ASSERT_TRUE(tests::sameFloats(a[f], b[f])) << "frame " << f;
    }
    // The lamps' settings differ, so the passes do draw different frames (the test can fail).
    bool switched = false;
    for (std::size_t i = 0; i < a[3].size(); ++i) {
        switched = switched || a[3][i] != a[1][i];
    }
    EXPECT_TRUE(switched);
    EXPECT_EQ((*warm)->cacheRefreshes(), (*cold)->cacheRefreshes());
    EXPECT_GT((*cold)->cacheRefreshes(), 0);
}

// The pass the first frame shows (BoothSceneSetup::firstLamp: the site's default lamp) is the one
// made at create(); it draws what a pass made in the default order draws, and what is left to
// compile lists the lamps' passes first, in lamp order, the one no lamp draws (variant 0: the
// direct-sensor mode's) last.
TEST_F(BoothWarmUpTest, TheFirstLampsPassComesFirstAndTheLampsPassesBeforeVariantZero)
{
    // Every lamp with a program of its own: tungsten (lamp 0, neither walls nor a specular term)
    // -> 1, d50 -> 2, d65 -> 3.
    setup_.perLamp["tungsten"] = LampSettings{16, 0, 0, false};
    ASSERT_EQ(setup_.booth.lights[0].name, "tungsten");
    auto plain = BoothScenePass::create(setup_);
    auto first = setup_;
    first.firstLamp = 2;
    auto d65First = BoothScenePass::create(first);
    ASSERT_TRUE(plain && d65First);
    ASSERT_EQ((*plain)->variantCount(), 4u);
    EXPECT_EQ((*plain)->variantsNotDrawn(), (std::vector<std::size_t>{1, 2, 3, 0}));
    EXPECT_EQ((*d65First)->variantsNotDrawn(), (std::vector<std::size_t>{1, 2, 3, 0}));
    const auto a = run(**plain);
    const auto b = run(**d65First);
    ASSERT_EQ(a.size(), b.size());
    for (std::size_t f = 0; f < a.size(); ++f) {
        ASSERT_TRUE(tests::sameFloats(a[f], b[f])) << "frame " << f;
    }
    // run() drew lamps 0, 1 and 2: variant 0 is left, and only it.
    EXPECT_EQ((*d65First)->variantsNotDrawn(), (std::vector<std::size_t>{0}));
}

} // namespace
} // namespace replica::pipeline::render
