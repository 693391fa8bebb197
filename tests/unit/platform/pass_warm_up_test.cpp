// The shading passes compiled around the first frame (platform/output/pass_warm_up.h): a thread of
// its own compiling the other lamps' passes in its own EGL context while the loop switches lamps at
// once, and the loop's idle-time warm-ups between frames, change no frame of the renderer (XYZ and
// the display's counts, bit for bit, across switches between passes of different settings) and,
// once done, leave no switch that compiles.
#include <chrono>
#include <thread>

#include <pipeline/display/nominal_display.h>
#include <pipeline/render/gles_renderer.h>
#include <pipeline/scene/booth.h>
#include <platform/output/pass_warm_up.h>

#include <gtest/gtest.h>

#include "../support/headless_gl.h"

namespace replica::platform {
namespace {

namespace pr = pipeline::render;

class PassWarmUpTest : public tests::HeadlessGlTest
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
        // Three passes: the setup's (walls and a specular term; tungsten draws it), and one of its
        // own for each fluorescent: d50 without the walls, d65 without the specular term.
        setup_.booth.walls = pipeline::scene::defaultBoothWalls(setup_.booth.ceiling());
        setup_.perLamp["d50-fluorescent"] = pr::LampSettings{8, 24, 0, false};
        setup_.perLamp["d65-fluorescent"] = pr::LampSettings{32, 0, 0, true};
    }

    // A renderer (64 x 40) whose pass 1 is a booth pass of setup_; 'scene' is that pass.
    std::unique_ptr<pr::Renderer> make(std::shared_ptr<pr::BoothScenePass>& scene)
    {
        pr::GlesRendererSetup s = tests::rendererSetup("colorchecker");
        s.display.model = pipeline::display::nominalDisplayModel("srgb-like-800", 800.0, 0.4);
        auto pass = pr::BoothScenePass::create(setup_);
        EXPECT_TRUE(pass);
        if (!pass) {
            return nullptr;
        }
        scene = std::move(*pass);
        s.boothScene = scene;
        auto r = pr::createGlesRenderer(s);
        EXPECT_TRUE(r) << (r ? "" : r.error().message);
        return r ? std::move(*r) : nullptr;
    }

    static pipeline::scene::SceneState state(int lamp, int i)
    {
        pipeline::scene::SceneState st;
        st.lampIndex = lamp;
        st.tiltRad = 0.30 + 0.02 * i;
        st.eyeBoothM = {-0.2 + 0.05 * i, 0.45, 0.60};
        return st;
    }

    pr::BoothSceneSetup setup_;
};

// Lamp 0, then at once 1, 2, 0, 2, 1 while the thread compiles passes 1 and 2 in its own context.
TEST_F(PassWarmUpTest, SwitchingWhileTheThreadCompilesChangesNoFrame)
{
    std::shared_ptr<pr::BoothScenePass> coldScene;
    std::shared_ptr<pr::BoothScenePass> scene;
    auto cold = make(coldScene);
    auto r = make(scene);
    ASSERT_TRUE(cold && r);
    ASSERT_EQ(scene->variantCount(), 3u);
    pr::RenderedFrame a;
    pr::RenderedFrame b;
    ASSERT_TRUE(r->render(state(0, 0), b, pr::Readback::DisplayAndXyz));
    EXPECT_EQ(scene->firstUseDraws(), 1);
    const auto notDrawn = scene->variantsNotDrawn();
    ASSERT_EQ(notDrawn, (std::vector<std::size_t>{1, 2}));
    auto thread = BackgroundPassCompile::start(*scene, notDrawn, 64, 40);
    ASSERT_TRUE(thread) << thread.error().message;
    const int lamps[] = {0, 1, 2, 0, 2, 1};
    for (int i = 0; i < 6; ++i) {
        ASSERT_TRUE(cold->render(state(lamps[i], i), a, pr::Readback::DisplayAndXyz));
        ASSERT_TRUE(r->render(state(lamps[i], i), b, pr::Readback::DisplayAndXyz));
        ASSERT_EQ(a.xyz, b.xyz) << "frame " << i;
        ASSERT_EQ(a.rgba, b.rgba) << "frame " << i;
    }
    auto ms = (*thread)->result();
    ASSERT_TRUE(ms) << ms.error().message;
    EXPECT_GT(*ms, 0.0);
    // The loop's own context compiled each pass at its first draw (the thread's code is not
    // shared): three first-use frames, the same as the pass with no thread.
    EXPECT_EQ(scene->firstUseDraws(), 3);
    EXPECT_EQ(coldScene->firstUseDraws(), 3);
    EXPECT_TRUE(scene->variantsNotDrawn().empty());
    EXPECT_EQ(scene->cacheRefreshes(), coldScene->cacheRefreshes());
}

// The run's driver: after frame 1 the thread, then one idle-time warm-up per frame; then switches
// compile nothing and every frame is the one a pass with no warm-up draws.
TEST_F(PassWarmUpTest, IdleWarmUpsLeaveNoSwitchToCompileAndChangeNoFrame)
{
    if (mesaShaderCacheDisabled()) {
        GTEST_SKIP() << "Mesa's shader cache is off: the passes compile at their first use";
    }
    std::shared_ptr<pr::BoothScenePass> coldScene;
    std::shared_ptr<pr::BoothScenePass> scene;
    auto cold = make(coldScene);
    auto r = make(scene);
    ASSERT_TRUE(cold && r);
    PassWarmUp warmUp(scene, 64, 40);
    pr::RenderedFrame a;
    pr::RenderedFrame b;
    int i = 0;
    const auto frame = [&](int lamp) {
        ASSERT_TRUE(cold->render(state(lamp, i), a, pr::Readback::DisplayAndXyz));
        ASSERT_TRUE(r->render(state(lamp, i), b, pr::Readback::DisplayAndXyz));
        ASSERT_EQ(a.xyz, b.xyz) << "frame " << i;
        ASSERT_EQ(a.rgba, b.rgba) << "frame " << i;
        ++i;
        warmUp.afterFrame(static_cast<std::uint64_t>(i));
    };
    // Lamp 2 first: the passes left are 0 and 1.
    ASSERT_NO_FATAL_FAILURE(frame(2));
    // Frames 50 ms apart (the thread at the lowest priority runs in the gaps) for at most 10 min.
    const auto until = std::chrono::steady_clock::now() + std::chrono::minutes(10);
    while (warmUp.idleWarmUps() < 2 && std::chrono::steady_clock::now() < until) {
        ASSERT_NO_FATAL_FAILURE(frame(2));
        std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
    ASSERT_EQ(warmUp.idleWarmUps(), 2);
    EXPECT_TRUE(scene->variantsNotDrawn().empty());
    for (int lamp : {0, 1, 2, 1, 0}) {
        ASSERT_NO_FATAL_FAILURE(frame(lamp));
    }
    EXPECT_EQ(scene->firstUseDraws(), 1); // the first frame only
    EXPECT_EQ(warmUp.compilingFrames(), 1);
    EXPECT_EQ(coldScene->firstUseDraws(), 3);
    EXPECT_EQ(scene->cacheRefreshes(), coldScene->cacheRefreshes());
    warmUp.finish();
}

// Stopped before it is done (a run shorter than the compile): the destructor waits for the pass
// under way and nothing else is compiled.
TEST_F(PassWarmUpTest, StopsWhenTheRunEnds)
{
    std::shared_ptr<pr::BoothScenePass> scene;
    auto r = make(scene);
    ASSERT_TRUE(r);
    pr::RenderedFrame b;
    ASSERT_TRUE(r->render(state(0, 0), b, pr::Readback::Display));
    PassWarmUp warmUp(scene, 64, 40);
    warmUp.afterFrame(1);
    warmUp.finish();
    warmUp.afterFrame(2); // nothing left to wait for: the loop goes on with no warm-up
    EXPECT_EQ(warmUp.idleWarmUps(), 0);
}

} // namespace
} // namespace replica::platform
