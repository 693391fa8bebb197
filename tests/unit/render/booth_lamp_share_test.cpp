// Lamps whose plans differ only in their counts of lights and specular samples share one shading
// pass (BoothScenePass, booth_scene_pass.h), written out for the fewest counts and looping to each
// lamp's own: a switch between them compiles nothing, and every frame is, bit for bit, the frame a
// pass made for that lamp alone draws (written out for its own counts), so replay, which draws a
// frame from its state with a fresh pass, is unchanged.
#include <vector>

#include <pipeline/render/booth_scene_pass.h>
#include <pipeline/render/booth_shading_pass.h>
#include <pipeline/shading/realtime_model.h>

#include <gtest/gtest.h>

#include "../support/headless_gl.h"

namespace replica::pipeline::render {
namespace {

constexpr int kW = 48, kH = 30;

class BoothLampShareTest : public tests::HeadlessGlTest
{
protected:
    static scene::SceneState state(int lamp, int i)
    {
        scene::SceneState st;
        st.lampIndex = lamp;
        st.tiltRad = 0.30 + 0.02 * i;
        st.eyeBoothM = {-0.2 + 0.05 * i, 0.45, 0.60};
        return st;
    }

    // The setup with every lamp drawn with 'lamp's counts and no plan of its own: a pass written
    // out for those counts alone.
    static BoothSceneSetup alone(const BoothSceneSetup& setup, const LampSettings& lamp)
    {
        BoothSceneSetup s = setup;
        s.perLamp.clear();
        s.settings.lights = lamp.lights;
        s.settings.specularSamples = lamp.specularSamples;
        if (lamp.horizonDirections > 0) {
            s.settings.horizonDirections = lamp.horizonDirections;
        }
        return s;
    }

    // Lamps 0, 1, 2, 0, 2, 1 (-1: the direct-sensor mode, at the setup's counts) through one pass
    // made from 'setup', the eye and the tilt moving: one compiling frame, and each frame that of
    // a fresh pass for its lamp alone.
    static void expectSharedAndExact(const BoothSceneSetup& setup)
    {
        auto shared = BoothScenePass::create(setup);
        ASSERT_TRUE(shared) << shared.error().message;
        ASSERT_EQ((*shared)->variantCount(), 1u);
        const int lamps[] = {0, 1, 2, 0, 2, 1, -1};
        std::vector<std::vector<colour::Xyz>> frames;
        for (int i = 0; i < 7; ++i) {
            scene::SceneState st = state(lamps[i], i);
            if (lamps[i] < 0) {
                const auto& ceiling = setup.booth.lights.front();
                st.illuminant = ceiling.spd;
                st.emitterLuminanceCdM2 = 2000.0;
            }
            frames.push_back(tests::drawXyz(**shared, st, kW, kH));
            const std::string name =
                    lamps[i] < 0 ? std::string()
                                 : setup.booth.lights[static_cast<std::size_t>(lamps[i])].name;
            const auto it = setup.perLamp.find(name);
            ASSERT_TRUE(lamps[i] < 0 || it != setup.perLamp.end());
            const LampSettings own = lamps[i] < 0 ? LampSettings{setup.settings.lights,
                                                                 setup.settings.specularSamples, 0}
                                                  : it->second;
            auto fresh = BoothScenePass::create(alone(setup, own));
            ASSERT_TRUE(fresh) << fresh.error().message;
            const auto want = tests::drawXyz(**fresh, st, kW, kH);
            ASSERT_EQ(frames.back().size(), want.size());
            for (std::size_t p = 0; p < want.size(); ++p) {
                ASSERT_TRUE(frames.back()[p].x == want[p].x && frames.back()[p].y == want[p].y &&
                            frames.back()[p].z == want[p].z)
                        << "frame " << i << " (lamp " << lamps[i] << "), pixel " << p;
            }
        }
        // The first frame compiled the one pass; no switch compiled another.
        EXPECT_EQ((*shared)->firstUseDraws(), 1);
        EXPECT_TRUE((*shared)->variantsNotDrawn().empty());
        // The counts do reach the frame (the test can fail): the lamps' frames differ from what
        // lamp 0's counts would draw under lamp 1's light.
        auto other = BoothScenePass::create(alone(setup, setup.perLamp.begin()->second));
        ASSERT_TRUE(other);
        bool differs = false;
        for (int i : {1, 2}) {
            const auto wrongCounts = tests::drawXyz(**other, state(lamps[i], i), kW, kH);
            for (std::size_t p = 0; p < wrongCounts.size(); ++p) {
                differs = differs || wrongCounts[p].y != frames[static_cast<std::size_t>(i)][p].y;
            }
        }
        EXPECT_TRUE(differs);
    }
};

// The ColorChecker as the appliance draws it (the specular term at the grid's nodes, its samples
// in a loop), with the shipped plan's counts: 8 lights each, 24 / 48 / 32 specular samples.
TEST_F(BoothLampShareTest, TheColorCheckersLampsShareOnePassAndDrawTheirOwnFrames)
{
    BoothSceneSetup setup = tests::boothPassSetup("colorchecker");
    setup.settings.specularSamples = 16;
    setup.settings.specularGrid = shading::defaultSpecularGrid(setup.scene);
    setup.settings.diffuseGrid = shading::defaultDiffuseGrid(setup.scene);
    ASSERT_GT(setup.settings.specularGrid, 0);
    setup.perLamp["tungsten"] = LampSettings{8, 24, 0};
    setup.perLamp["d50-fluorescent"] = LampSettings{8, 48, 0};
    setup.perLamp["d65-fluorescent"] = LampSettings{16, 32, 0};
    expectSharedAndExact(setup);
}

// A relief with the specular term at every pixel (the glossy cylinder), with its plan's counts:
// 16 / 32 / 128 lights and 16 / 24 / 48 specular samples, 8 horizon directions each. The shared
// pass writes out 16 samples (the fewest), the rest in its loop; a pass of a lamp alone writes out
// its own (up to 32): the same sums.
TEST_F(BoothLampShareTest, TheGlossyCylindersLampsShareOnePassAndDrawTheirOwnFrames)
{
    BoothSceneSetup setup = tests::boothPassSetup("glossy-cylinder");
    setup.settings.specularSamples = 16;
    setup.settings.horizonDirections = 8;
    setup.perLamp["tungsten"] = LampSettings{16, 16, 8};
    setup.perLamp["d50-fluorescent"] = LampSettings{32, 24, 8};
    setup.perLamp["d65-fluorescent"] = LampSettings{128, 48, 8};
    expectSharedAndExact(setup);
}

// What a program is made of still makes a pass of its own: a lamp without the specular term, or
// with other horizon directions; counts alone do not.
TEST_F(BoothLampShareTest, APlanThatChangesTheProgramsMakesAPassOfItsOwn)
{
    BoothSceneSetup setup = tests::boothPassSetup("glossy-cylinder");
    setup.settings.horizonDirections = 8;
    setup.settings.specularSamples = 16;
    setup.perLamp["tungsten"] = LampSettings{64, 48, 8};        // the setup's pass
    setup.perLamp["d50-fluorescent"] = LampSettings{32, 0, 8};  // no specular term
    setup.perLamp["d65-fluorescent"] = LampSettings{32, 24, 4}; // 4 horizon directions
    auto pass = BoothScenePass::create(setup);
    ASSERT_TRUE(pass) << pass.error().message;
    EXPECT_EQ((*pass)->variantCount(), 3u);
}

// The counts a pass takes at run time are checked: lights 1 to 256; specular samples, in a pass
// made with a specular term, from those its programs write out to 256 (on relief, where they are
// written out per pixel: fewer would read past the table); the pass draws on with what it had.
TEST_F(BoothLampShareTest, CountsOutOfRangeAreRefused)
{
    const BoothSceneSetup setup = tests::boothPassSetup("colorchecker");
    const auto ps = shading::prepareScene(setup.scene, 1, 0.01, setup.basis);
    shading::RenderSettings settings = setup.settings;
    settings.specularSamples = 8;
    auto pass = BoothShadingPass::create(ps, settings, setup.observer);
    ASSERT_TRUE(pass) << pass.error().message;
    EXPECT_FALSE((*pass)->setCounts(0, 8));
    EXPECT_FALSE((*pass)->setCounts(257, 8));
    EXPECT_FALSE((*pass)->setCounts(16, 0));
    EXPECT_FALSE((*pass)->setCounts(16, 257));
    EXPECT_EQ((*pass)->settings().lights, settings.lights);
    EXPECT_EQ((*pass)->settings().specularSamples, 8);
    ASSERT_TRUE((*pass)->setCounts(24, 12));
    EXPECT_EQ((*pass)->settings().lights, 24);
    EXPECT_EQ((*pass)->settings().specularSamples, 12);

    const BoothSceneSetup relief = tests::boothPassSetup("glossy-cylinder");
    const auto rs = shading::prepareScene(relief.scene, 4, 0.01, relief.basis);
    shading::RenderSettings reliefSettings = relief.settings;
    reliefSettings.specularSamples = 24;
    reliefSettings.horizonDirections = 4;
    reliefSettings.specularGrid = 0; // per pixel, as the painting draws (the cylinder's is 2)
    auto perPixel = BoothShadingPass::create(rs, reliefSettings, relief.observer);
    ASSERT_TRUE(perPixel) << perPixel.error().message;
    EXPECT_EQ((*perPixel)->writtenOutSamples(), 24); // per pixel on relief: all 24 written out
    EXPECT_FALSE((*perPixel)->setCounts(8, 23));
    EXPECT_TRUE((*perPixel)->setCounts(8, 24));
}

} // namespace
} // namespace replica::pipeline::render
