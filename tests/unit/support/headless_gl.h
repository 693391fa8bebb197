// What the GL tests share: a fixture that owns a headless EGL/GLES 3.1 context (the test is skipped
// on a machine without one), the booth pass's set-up from the shipped data, a small sim run, and
// reading frames back.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include <pipeline/colour/xyz.h>
#include <pipeline/render/booth_scene_pass.h>
#include <pipeline/render/gles_renderer.h>
#include <pipeline/render/xyz_target.h>
#include <pipeline/scene/stand.h>
#include <platform/appliance.h>
#include <platform/output/output.h>

#include <gtest/gtest.h>

namespace replica::tests {

// A derived fixture's SetUp calls HeadlessGlTest::SetUp() first and returns when IsSkipped().
class HeadlessGlTest : public ::testing::Test
{
protected:
    void SetUp() override;

    std::unique_ptr<platform::Output> output_;
};

// The booth pass as the appliance sets it up, from the shipped data: the booth (a state's
// lampIndex indexes its lights), 'scene' from data/scenes, the default channel basis, the CIE 1931
// observer, 16 lights; every other setting at its default.
pipeline::render::BoothSceneSetup boothPassSetup(const std::string& scene);

// The renderer's set-up at 64 x 40 pixels: pass 1 the booth pass of 'scene' (boothPassSetup,
// created here: the context must be current), the CIE 1931 observer; the display is the test's.
pipeline::render::GlesRendererSetup rendererSetup(const std::string& scene);

// A short, small sim run that still draws the booth pass: 32x20 at 10 Hz, 8 lights, 2 specular
// samples, 4 horizon directions.
platform::RunConfig smallSimRun();

// Every float of the RGBA32F target (alpha included), rows as GL has them.
std::vector<float> readFloats(const pipeline::render::XyzTarget& target);

// The frame 'pass' draws of 'st' into a fresh width x height target, as XYZ.
std::vector<pipeline::colour::Xyz> drawXyz(pipeline::render::BoothScenePass& pass,
                                           const pipeline::scene::SceneState& st,
                                           int width,
                                           int height);

// Bit for bit the same frame, or where the first float differs (a whole frame in a failure
// message is thousands of numbers).
::testing::AssertionResult sameFloats(const std::vector<float>& got,
                                      const std::vector<float>& want);

} // namespace replica::tests
