#include "headless_gl.h"

#include <pipeline/base/data_dir.h>

namespace replica::tests {

void HeadlessGlTest::SetUp()
{
    auto out = platform::createHeadlessOutput();
    if (!out) {
        GTEST_SKIP() << "no EGL/GLES 3.1 context: " << out.error().message;
    }
    output_ = std::move(*out);
}

pipeline::render::BoothSceneSetup boothPassSetup(const std::string& scene)
{
    pipeline::render::BoothSceneSetup setup;
    auto booth = pipeline::booth::loadBooth(dataDir() / "booth");
    auto surface = pipeline::surface::loadScene(dataDir() / "scenes" / scene);
    auto basis = pipeline::colour::loadDefaultChannelBasis(dataDir());
    auto observer = pipeline::colour::loadCie1931(dataDir());
    EXPECT_TRUE(booth && surface && basis && observer) << "shipped data for scene " << scene;
    if (booth && surface && basis && observer) {
        setup.booth = *booth;
        setup.scene = *surface;
        setup.basis = *basis;
        setup.observer = *observer;
    }
    setup.settings.lights = 16;
    return setup;
}

pipeline::render::GlesRendererSetup rendererSetup(const std::string& scene)
{
    pipeline::render::GlesRendererSetup s;
    s.width = 64;
    s.height = 40;
    const auto passSetup = boothPassSetup(scene);
    s.stand = passSetup.stand;
    s.observer = passSetup.observer;
    auto pass = pipeline::render::BoothScenePass::create(passSetup);
    EXPECT_TRUE(pass) << (pass ? "" : pass.error().message);
    if (pass) {
        s.boothScene = std::move(*pass);
    }
    return s;
}

platform::RunConfig smallSimRun()
{
    platform::RunConfig config;
    config.width = 32;
    config.height = 20;
    config.rateHz = 10.0;
    config.boothLights = 8;
    config.specularSamples = 2;
    config.horizonDirections = 4;
    return config;
}

std::vector<float> readFloats(const pipeline::render::XyzTarget& target)
{
    std::vector<float> px(static_cast<std::size_t>(target.width()) * target.height() * 4);
    target.bind();
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    glReadPixels(0, 0, target.width(), target.height(), GL_RGBA, GL_FLOAT, px.data());
    return px;
}

std::vector<pipeline::colour::Xyz> drawXyz(pipeline::render::BoothScenePass& pass,
                                           const pipeline::scene::SceneState& st,
                                           int width,
                                           int height)
{
    auto target = pipeline::render::XyzTarget::create(width, height);
    EXPECT_TRUE(target);
    if (!target) {
        return {};
    }
    (*target)->bind();
    auto ok = pass.draw(st, width, height);
    EXPECT_TRUE(ok) << (ok ? "" : ok.error().message);
    return (*target)->read({}, {}).xyz;
}

::testing::AssertionResult sameFloats(const std::vector<float>& got, const std::vector<float>& want)
{
    if (got.size() != want.size()) {
        return ::testing::AssertionFailure() << "sizes " << got.size() << " and " << want.size();
    }
    for (std::size_t i = 0; i < got.size(); ++i) {
        if (!(got[i] == want[i])) {
            return ::testing::AssertionFailure() << "pixel " << i / 4 << " channel " << i % 4
                                                 << ": " << got[i] << " against " << want[i];
        }
    }
    return ::testing::AssertionSuccess();
}

} // namespace replica::tests
