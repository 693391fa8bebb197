// The loop's booth pass: lamp -> booth light, unknown -> sensed spectrum on a uniform emitter, and
// the appliance configuration that records the scene for replay.
#include <cmath>
#include <filesystem>
#include <fstream>
#include <optional>
#include <utility>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <pipeline/base/data_dir.h>
#include <pipeline/render/booth_scene_pass.h>
#include <pipeline/render/render_profile.h>
#include <platform/appliance.h>

#include <gtest/gtest.h>

#include "../support/headless_gl.h"

namespace replica::pipeline::render {
namespace {

class BoothScenePassTest : public tests::HeadlessGlTest
{
protected:
    void SetUp() override
    {
        tests::HeadlessGlTest::SetUp();
        if (IsSkipped()) {
            return;
        }
        setup_ = tests::boothPassSetup("metamer");
    }

    static std::vector<colour::Xyz> frame(BoothScenePass& pass, const scene::SceneState& st)
    {
        return tests::drawXyz(pass, st, kW, kH);
    }

    static constexpr int kW = 52, kH = 32;
    BoothSceneSetup setup_;
};

TEST_F(BoothScenePassTest, ClassifiedLampUsesItsBoothLight)
{
    auto pass = BoothScenePass::create(setup_);
    ASSERT_TRUE(pass) << pass.error().message;
    scene::SceneState st;
    st.lampIndex = 2;
    st.tiltRad = 0.5;
    const auto got = frame(**pass, st);

    // The same light, view and layout through the shading pass directly.
    const auto ps = shading::prepareScene(setup_.scene, 8, 0.01, setup_.basis);
    auto direct = BoothShadingPass::create(ps, setup_.settings, setup_.observer);
    ASSERT_TRUE(direct);
    const auto pl = shading::prepareLight(*setup_.booth.find("d65-fluorescent"), setup_.observer,
                                          16, setup_.basis);
    ASSERT_TRUE((*direct)->setLight(pl));
    auto target = XyzTarget::create(kW, kH);
    ASSERT_TRUE(target);
    (*target)->bind();
    shading::View v;
    v.panel = scene::panelPose(setup_.stand, 0.5);
    v.eye = st.eyeBoothM;
    ASSERT_TRUE((*direct)->draw(v, kW, kH, layoutOnPanel(setup_.scene, setup_.stand)));
    const auto want = (*target)->read({}, {}).xyz;
    ASSERT_EQ(got.size(), want.size());
    double lit = 0.0;
    for (std::size_t i = 0; i < got.size(); ++i) {
        ASSERT_EQ(got[i].y, want[i].y) << i;
        lit += got[i].y;
    }
    EXPECT_GT(lit, 0.0);
}

// The scene prepared once and reprojected (the automatic dimmer's probe views and the pass's first
// variant share it) is the scene prepared anew in the other basis, value for value.
TEST(ReprojectScene, IsTheScenePreparedAnewInTheOtherBasis)
{
    const auto setup = tests::boothPassSetup("painting");
    ASSERT_FALSE(setup.scene.flat());
    const auto box = shading::prepareScene(setup.scene, 8, 0.01, colour::boxBasis());
    const auto got = shading::reprojectScene(box, setup.scene, setup.basis);
    const auto want = shading::prepareScene(setup.scene, 8, 0.01, setup.basis);
    EXPECT_EQ(got.scene, &setup.scene);
    EXPECT_EQ(got.normals, want.normals);
    EXPECT_EQ(got.horizon.directions, 8);
    EXPECT_EQ(got.horizon.sinBeta, want.horizon.sinBeta);
    EXPECT_EQ(got.horizonHalf.sinBeta, want.horizonHalf.sinBeta);
    ASSERT_EQ(got.paletteCoeffs.size(), want.paletteCoeffs.size());
    ASSERT_FALSE(want.paletteCoeffs.empty());
    bool differs = false; // the box basis's coefficients are not the setup basis's
    for (std::size_t i = 0; i < want.paletteCoeffs.size(); ++i) {
        EXPECT_EQ(got.paletteCoeffs[i], want.paletteCoeffs[i]) << i;
        differs = differs || box.paletteCoeffs[i] != want.paletteCoeffs[i];
    }
    EXPECT_TRUE(differs);
}

// A pass handed the prepared scene (BoothSceneSetup::prepared) draws what one that prepares it
// itself draws, bit for bit; one with other horizon directions prepares its own.
class BoothScenePassPrepared : public tests::HeadlessGlTest
{
};

TEST_F(BoothScenePassPrepared, DrawsTheSameFramesAsOneThatPreparesTheSceneItself)
{
    auto setup = tests::boothPassSetup("painting");
    auto own = BoothScenePass::create(setup);
    ASSERT_TRUE(own) << own.error().message;
    for (const int directions : {setup.settings.horizonDirections, 4}) {
        SCOPED_TRACE(directions);
        auto given = setup;
        given.prepared = std::make_shared<const shading::PreparedScene>(
                shading::prepareScene(setup.scene, directions, 0.01, colour::boxBasis()));
        auto shared = BoothScenePass::create(given);
        ASSERT_TRUE(shared) << shared.error().message;
        scene::SceneState st;
        st.lampIndex = 1;
        st.tiltRad = 0.3;
        const auto a = tests::drawXyz(**own, st, 52, 32);
        const auto b = tests::drawXyz(**shared, st, 52, 32);
        ASSERT_EQ(a.size(), b.size());
        double lit = 0.0;
        for (std::size_t i = 0; i < a.size(); ++i) {
            ASSERT_EQ(a[i].x, b[i].x) << i;
            ASSERT_EQ(a[i].y, b[i].y) << i;
            ASSERT_EQ(a[i].z, b[i].z) << i;
            lit += a[i].y;
        }
        EXPECT_GT(lit, 0.0);
    }
}

TEST_F(BoothScenePassTest, ABoothThatDeclaresItsWallsIsLitByThemToo)
{
    // The shipped booth declares none: its frames stay as they were.
    ASSERT_FALSE(setup_.booth.walls.has_value());
    scene::SceneState st;
    st.lampIndex = 0;
    st.tiltRad = 0.5;
    auto plain = BoothScenePass::create(setup_);
    ASSERT_TRUE(plain) << plain.error().message;
    EXPECT_FALSE((*plain)->setup().settings.walls);
    const auto without = frame(**plain, st);
    BoothSceneSetup walled = setup_;
    walled.booth.walls = scene::defaultBoothWalls(walled.booth.ceiling());
    auto pass = BoothScenePass::create(walled);
    ASSERT_TRUE(pass) << pass.error().message;
    EXPECT_TRUE((*pass)->setup().settings.walls);
    const auto with = frame(**pass, st);
    ASSERT_EQ(with.size(), without.size());
    double a = 0.0, b = 0.0;
    for (std::size_t i = 0; i < with.size(); ++i) {
        a += without[i].y;
        b += with[i].y;
    }
    // N7 walls add a few percent to the frame.
    EXPECT_GT(b, 1.01 * a);
    EXPECT_LT(b, 1.3 * a);

    // A lamp whose plan leaves the walls out draws as under a booth without them, bit for bit;
    // the other lamps keep them.
    BoothSceneSetup planned = walled;
    LampSettings off;
    off.lights = setup_.settings.lights;
    off.specularSamples = setup_.settings.specularSamples;
    off.horizonDirections = setup_.settings.horizonDirections;
    off.walls = false;
    planned.perLamp[walled.booth.lights[0].name] = off;
    auto mixed = BoothScenePass::create(planned);
    ASSERT_TRUE(mixed) << mixed.error().message;
    const auto left = frame(**mixed, st);
    ASSERT_EQ(left.size(), without.size());
    for (std::size_t i = 0; i < left.size(); ++i) {
        ASSERT_EQ(left[i].x, without[i].x) << i;
        ASSERT_EQ(left[i].y, without[i].y) << i;
        ASSERT_EQ(left[i].z, without[i].z) << i;
    }
    scene::SceneState other = st;
    other.lampIndex = 1;
    const auto kept = frame(**mixed, other);
    const auto keptWalled = frame(**pass, other);
    ASSERT_EQ(kept.size(), keptWalled.size());
    for (std::size_t i = 0; i < kept.size(); ++i) {
        ASSERT_EQ(kept[i].y, keptWalled[i].y) << i;
    }
}

TEST_F(BoothScenePassTest, UnknownLightIsTheSensedSpectrumOnAUniformEmitter)
{
    auto pass = BoothScenePass::create(setup_);
    ASSERT_TRUE(pass);
    scene::SceneState st;
    st.lampIndex = -1;
    st.tiltRad = 0.3;
    for (std::size_t b = 0; b < colour::kBands; ++b) {
        st.illuminant[b] = 1.0 + 0.02 * static_cast<double>(b); // a sensed shape no lamp has
    }
    st.emitterLuminanceCdM2 = 1000.0;
    const auto a = frame(**pass, st);
    st.emitterLuminanceCdM2 = 2000.0;
    const auto b = frame(**pass, st);
    // Linear in the emitter's luminance (a changed light is re-prepared, not cached).
    long lit = 0;
    for (std::size_t i = 0; i < a.size(); ++i) {
        ASSERT_TRUE(std::isfinite(b[i].y));
        if (a[i].y > 1.0) {
            EXPECT_NEAR(b[i].y / a[i].y, 2.0, 1e-4);
            ++lit;
        }
    }
    EXPECT_GT(lit, kW * kH / 8);
    // The uniform emitter keeps the booth light's geometry.
    const auto e = uniformEmitter(setup_.booth.lights[0], 1000.0, st.illuminant);
    EXPECT_EQ(e.centre, setup_.booth.lights[0].centre);
    EXPECT_DOUBLE_EQ(e.luminance.max(), 1000.0);
}

TEST(ApplianceConfig, TheFlatRenderersRecordingsAreMarkedAndScenesAreDigested)
{
    platform::RunConfig c;
    std::string json = c.toJson();
    // A configuration written before the booth renderer has none of its keys.
    for (const char* key : {"renderer", "scene_dir", "scene_digest", "booth_lights",
                            "specular_samples", "horizon_directions"}) {
        ASSERT_NE(json.find(key), std::string::npos);
    }
    auto parsed = platform::RunConfig::fromJson(json);
    ASSERT_TRUE(parsed);
    EXPECT_FALSE(parsed->drawnByFlatRenderer);
    EXPECT_EQ(json.find("lights_u"), std::string::npos); // the flat renderer's grid: gone
    const std::string old =
            R"({"width":160,"height":100,"rate_hz":60.0,"booth":"replica-booth-1",)"
            R"("scene":"colorchecker","basis":"box6","lights_u":8,"lights_v":4,)"
            R"("spectrometer_calibration":"x.csv","display":"d","display_peak_cd_m2":800.0,)"
            R"("display_black_cd_m2":0.4})";
    auto o = platform::RunConfig::fromJson(old);
    ASSERT_TRUE(o) << o.error().message;
    // The flat renderer drew it: replay draws the shipped ColorChecker with the booth pass.
    EXPECT_TRUE(o->drawnByFlatRenderer);
    EXPECT_EQ(o->sceneDir, "scenes/colorchecker");
    // So does a recording that names it, whatever scene it names (the flat renderer drew its own
    // ColorChecker patches); another renderer's name is refused.
    auto named = nlohmann::json::parse(json);
    named["renderer"] = "flat";
    named["scene_dir"] = "scenes/painting";
    auto flat = platform::RunConfig::fromJson(named.dump());
    ASSERT_TRUE(flat) << flat.error().message;
    EXPECT_TRUE(flat->drawnByFlatRenderer);
    EXPECT_EQ(flat->sceneDir, "scenes/colorchecker");
    EXPECT_TRUE(flat->sceneDigest.empty());
    named["renderer"] = "ray";
    auto unknown = platform::RunConfig::fromJson(named.dump());
    ASSERT_FALSE(unknown);
    EXPECT_NE(unknown.error().message.find("renderer 'ray' is not 'booth' or 'flat'"),
              std::string::npos)
            << unknown.error().message;
    // Every other absent key is today's default: this build has one render path, and the
    // recording's render profile (0: none recorded) says its frames are approximate here.
    const platform::RunConfig today;
    EXPECT_EQ(o->specularGrid, today.specularGrid);
    EXPECT_EQ(o->diffuseGrid, today.diffuseGrid);
    EXPECT_EQ(o->areaLights, today.areaLights);
    EXPECT_EQ(o->cacheSlices, today.cacheSlices);
    EXPECT_EQ(o->viewingCompensation, today.viewingCompensation);
    EXPECT_EQ(o->flareSubtraction, today.flareSubtraction);
    EXPECT_EQ(o->renderProfile, 0);
    EXPECT_FALSE(pipeline::render::rendersExactly(o->renderProfile));
    EXPECT_EQ(c.renderProfile, pipeline::render::kRenderProfile);
    EXPECT_TRUE(pipeline::render::rendersExactly(c.renderProfile));
    // Profile 0's switch keys are known (an older recording holds them) and not read.
    auto withSwitches = nlohmann::json::parse(old);
    withSwitches["hardware_filter"] = false;
    withSwitches["specular_lod_bias"] = 1.0;
    withSwitches["render_profile"] = 1;
    std::vector<std::string> warnings;
    auto o1 = platform::RunConfig::fromJson(withSwitches.dump(), &warnings);
    ASSERT_TRUE(o1) << o1.error().message;
    EXPECT_TRUE(warnings.empty()) << warnings.front();
    EXPECT_EQ(o1->renderProfile, 1);
    // A profile newer than this build's is refused in one line naming both.
    platform::RunConfig newer = c;
    newer.renderProfile = pipeline::render::kRenderProfile + 1;
    const auto refused = platform::RunConfig::fromJson(newer.toJson());
    ASSERT_FALSE(refused);
    EXPECT_NE(refused.error().message.find(fmt::format(
                      "render profile {} is newer than this build's ({})",
                      pipeline::render::kRenderProfile + 1, pipeline::render::kRenderProfile)),
              std::string::npos)
            << refused.error().message;
    EXPECT_EQ(refused.error().message.find('\n'), std::string::npos);
    for (const int area : {0, 1}) {
        platform::RunConfig chosen = c;
        chosen.areaLights = area;
        const auto back = platform::RunConfig::fromJson(chosen.toJson());
        ASSERT_TRUE(back);
        EXPECT_EQ(back->areaLights, area);
    }
    platform::RunConfig badArea = c;
    badArea.areaLights = 2;
    EXPECT_FALSE(platform::RunConfig::fromJson(badArea.toJson()));
    // A new run slices the cache's refresh.
    EXPECT_EQ(c.cacheSlices, platform::kDefaultCacheSlices);
    EXPECT_GT(c.cacheSlices, 1);
    for (const int slices : {1, 4, platform::kMaxCacheSlices}) {
        platform::RunConfig k = c;
        k.cacheSlices = slices;
        const auto back = platform::RunConfig::fromJson(k.toJson());
        ASSERT_TRUE(back) << slices;
        EXPECT_EQ(back->cacheSlices, slices);
    }
    for (const int slices : {0, -3, platform::kMaxCacheSlices + 1}) {
        platform::RunConfig k = c;
        k.cacheSlices = slices;
        const auto bad = platform::RunConfig::fromJson(k.toJson());
        ASSERT_FALSE(bad) << slices;
        EXPECT_NE(bad.error().message.find("/cache_slices: expected an integer in [1, 16]"),
                  std::string::npos)
                << bad.error().message;
    }
    // A new run chooses (the grid per scene when the appliance is built) and records both.
    EXPECT_EQ(c.specularGrid, platform::kAutoSpecularGrid);
    EXPECT_EQ(c.diffuseGrid, platform::kAutoDiffuseGrid);
    c.specularGrid = 8;
    c.diffuseGrid = 5;
    auto round = platform::RunConfig::fromJson(c.toJson());
    ASSERT_TRUE(round);
    EXPECT_EQ(round->specularGrid, 8);
    EXPECT_EQ(round->diffuseGrid, 5);
    c.specularGrid = -2;
    EXPECT_FALSE(platform::RunConfig::fromJson(c.toJson()));
    c.specularGrid = 8;
    c.diffuseGrid = 257;
    const auto badGrid = platform::RunConfig::fromJson(c.toJson());
    ASSERT_FALSE(badGrid);
    EXPECT_NE(badGrid.error().message.find("/diffuse_grid: expected an integer in [-1, 256]"),
              std::string::npos)
            << badGrid.error().message;

    const auto shipped = platform::resolveSceneDir("scenes/metamer");
    auto d1 = platform::sceneDigest(shipped);
    ASSERT_TRUE(d1);
    const auto copy = std::filesystem::temp_directory_path() / "replica_digest_scene";
    std::filesystem::remove_all(copy);
    std::filesystem::copy(shipped, copy);
    EXPECT_EQ(*platform::sceneDigest(copy), *d1);
    std::ofstream(copy / "height.exr", std::ios::app) << 'x';
    EXPECT_NE(*platform::sceneDigest(copy), *d1);
    std::filesystem::remove(copy / "material.exr");
    auto missing = platform::sceneDigest(copy);
    ASSERT_FALSE(missing);
    EXPECT_NE(missing.error().message.find("material.exr: cannot read the scene file"),
              std::string::npos);
    std::filesystem::remove_all(copy);
}

} // namespace
} // namespace replica::pipeline::render

namespace replica::platform {
namespace {

// One frame of a freshly built appliance (one GL context at a time: built, drawn, destroyed).
struct SurroundFrame {
    pipeline::render::RenderedFrame frame;
    pipeline::render::PixelRect rect;
    bool surround = true;
};
std::optional<SurroundFrame> surroundFrame(RunConfig c)
{
    auto app = buildAppliance(c);
    if (!app) {
        return std::nullopt;
    }
    pipeline::scene::SceneState st;
    st.lampIndex = 0;
    st.illuminant = (*app)->booth.lights[0].referenceSpectrum;
    st.emitterLuminanceCdM2 = (*app)->booth.lights[0].nominalLuminanceCdM2;
    st.tiltRad = 0.3;
    st.eyeBoothM = {0.1, 0.5, 0.45};
    SurroundFrame f;
    EXPECT_TRUE((*app)->renderer->render(st, f.frame, pipeline::render::Readback::DisplayAndXyz));
    f.rect = (*app)->boothScene->surfaceRect(c.width, c.height);
    f.surround = (*app)->boothScene->surroundIlluminance();
    return f;
}

TEST(ApplianceBoothScene, TheSurroundIsShadedOnlyWhereTheDisplayPassReadsIt)
{
    RunConfig c;
    c.width = 96;
    c.height = 60;
    const auto without = surroundFrame(c);
    if (!without) {
        GTEST_SKIP() << "no EGL/GLES context";
    }
    // The display pass clears the surround: the booth pass shades only the surface
    // (booth_cache_test shows the frame is the same either way).
    EXPECT_FALSE(without->surround);

    // A display pass that shades the surround (per-channel clipping) gets its illuminance
    // too.
    c.gamutMapping = "clip";
    const auto clip = surroundFrame(c);
    ASSERT_TRUE(clip);
    EXPECT_TRUE(clip->surround);
}

TEST(ApplianceConfig, EveryRecordedRenderSettingReachesTheRenderer)
{
    // What a recording holds is what its replay renders with: each key, set both ways, arrives
    // in the booth renderer's settings (a key dropped on the way renders every replay with the
    // default, which the committed goldens only catch where the default changes their frames).
    platform::RunConfig c;
    c.boothLights = 17;
    c.specularSamples = 5;
    c.specularGrid = 3;
    c.diffuseGrid = 2;
    c.horizonDirections = 12;
    for (const bool on : {false, true}) {
        c.areaLights = on ? 0 : 1;
        c.cacheSlices = on ? 3 : 1;
        c.flareSubtraction = !on;
        const pipeline::shading::RenderSettings s = platform::boothRenderSettings(c);
        EXPECT_EQ(s.lights, 17);
        EXPECT_EQ(s.specularSamples, 5);
        EXPECT_EQ(s.specularGrid, 3);
        EXPECT_EQ(s.diffuseGrid, 2);
        EXPECT_EQ(s.horizonDirections, 12);
        EXPECT_EQ(s.areaLights, !on);
        EXPECT_EQ(s.cacheSlices, on ? 3 : 1);
        // Flare subtracted by the display pass: never a second time in pass 1.
        EXPECT_EQ(s.subtractFlare, on);
    }
}

TEST(ApplianceBoothScene, ChoosesTheSpecularSampleCountForTheSceneAndRecordsIt)
{
    RunConfig c;
    EXPECT_EQ(c.specularSamples, kAutoSpecularSamples);
    c.width = 32;
    c.height = 20;
    c.sceneDir = "scenes/painting";
    auto app = buildAppliance(c);
    if (!app && app.error().message.find("EGL") != std::string::npos) {
        GTEST_SKIP() << app.error().message;
    }
    ASSERT_TRUE(app) << app.error().message;
    // Relief, shaded per pixel: the relief's count, recorded as chosen.
    EXPECT_EQ((*app)->config.specularSamples, pipeline::shading::kReliefSpecularSamples);
    EXPECT_NE((*app)->config.toJson().find("\"specular_samples\":8"), std::string::npos);
    EXPECT_NE((*app)->renderer->description().find(", 8 specular samples"), std::string::npos)
            << (*app)->renderer->description();
    // Relief sums eq. (1) per pixel: recorded as 0; and from point lights, recorded as chosen.
    EXPECT_EQ((*app)->config.diffuseGrid, 0);
    EXPECT_EQ((*app)->config.areaLights, 0);
    EXPECT_NE((*app)->config.toJson().find("\"area_lights\":0"), std::string::npos);
    app->reset();

    // A recording holds the count it ran with and replays with it, whatever the scene's default
    // (the flat ColorChecker here: quicker to build than the painting, and its default is 12).
    RunConfig flat;
    flat.width = 32;
    flat.height = 20;
    flat.specularSamples = 5;
    auto recorded = RunConfig::fromJson(flat.toJson());
    ASSERT_TRUE(recorded);
    EXPECT_EQ(recorded->specularSamples, 5);
    auto replayed = buildAppliance(*recorded);
    ASSERT_TRUE(replayed) << replayed.error().message;
    EXPECT_EQ((*replayed)->config.specularSamples, 5);
    // The flat ColorChecker's diffuse grid, chosen when the appliance is built and recorded.
    EXPECT_EQ((*replayed)->config.diffuseGrid, pipeline::shading::kFlatDiffuseGrid);
    EXPECT_NE((*replayed)->config.toJson().find("\"diffuse_grid\":8"), std::string::npos);
    EXPECT_EQ((*replayed)->config.areaLights, 1); // a flat surface: eq. (1) from areas
    EXPECT_NE((*replayed)->renderer->description().find(", diffuse grid 8 texels"),
              std::string::npos)
            << (*replayed)->renderer->description();
    EXPECT_NE((*replayed)->renderer->description().find(", 5 specular samples"), std::string::npos)
            << (*replayed)->renderer->description();

    // A count out of range is refused by name.
    recorded->specularSamples = -2;
    auto bad = RunConfig::fromJson(recorded->toJson());
    ASSERT_FALSE(bad);
    EXPECT_NE(bad.error().message.find("/specular_samples: expected an integer in [-1, 256]"),
              std::string::npos)
            << bad.error().message;
}

TEST(ApplianceBoothScene, RecordsTheSceneAndRefusesAChangedOne)
{
    RunConfig c;
    c.width = 32;
    c.height = 20;
    c.sceneDir = "scenes/metamer";
    auto app = buildAppliance(c);
    if (!app && app.error().message.find("EGL") != std::string::npos) {
        GTEST_SKIP() << app.error().message;
    }
    ASSERT_TRUE(app) << app.error().message;
    // The configuration as built names the scene and its digest: what a recording stores.
    EXPECT_EQ((*app)->config.scene, "metamer");
    EXPECT_EQ((*app)->config.sceneDigest, *sceneDigest(resolveSceneDir("scenes/metamer")));
    EXPECT_NE((*app)->renderer->description().find("gles-booth (scene metamer"), std::string::npos);
    app->reset();

    c.sceneDigest = "0123456789abcdef";
    auto refused = buildAppliance(c);
    ASSERT_FALSE(refused);
    EXPECT_NE(refused.error().message.find("the scene has changed since it was recorded"),
              std::string::npos)
            << refused.error().message;
}

} // namespace
} // namespace replica::platform
