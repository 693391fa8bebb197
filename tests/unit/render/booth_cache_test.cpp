// The booth pass's cache of its eye-independent part: a frame drawn from the cache equals one that
// recomputes it, the cache follows light, pose and size, its bands and tilt nodes draw what the
// state names, and pass 1's illuminance in alpha is E_geo on every pixel of the panel. What the
// held tilt and the nodes cost in colour: tilt_cost_test.cpp.
#include <array>
#include <cmath>
#include <cstdint>
#include <numbers>

#include <state/tilt_estimator.h>

#include <pipeline/base/data_dir.h>
#include <pipeline/reference/frame_error.h>
#include <pipeline/render/booth_scene_pass.h>

#include <gtest/gtest.h>

#include "../support/headless_gl.h"
#include "../support/state_sequence.h"

namespace replica::pipeline::render {
namespace {

constexpr int kCacheW = 60, kCacheH = 36;

class BoothCacheTest : public tests::HeadlessGlTest
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
        setup_.settings.subtractFlare = false; // as in the appliance: pass 2 subtracts it
        auto t = XyzTarget::create(kCacheW, kCacheH);
        ASSERT_TRUE(t);
        target_ = std::move(*t);
    }

    std::vector<float> draw(BoothScenePass& pass, const scene::SceneState& st)
    {
        target_->bind();
        auto ok = pass.draw(st, kCacheW, kCacheH);
        EXPECT_TRUE(ok) << (ok ? "" : ok.error().message);
        return tests::readFloats(*target_);
    }

    std::unique_ptr<XyzTarget> target_;
    BoothSceneSetup setup_;
};

// The cache's two ways of running, as the appliance runs them: the ColorChecker with a diffuse
// grid (mode 3 drawn with the first band) and the surround's illuminance, and the painting
// (relief, the facet cache) without it.
struct CacheCase {
    const char* scene;
    int diffuseGrid;
    bool surround;
};
constexpr std::array kCacheCases{CacheCase{"colorchecker", 4, true},
                                 CacheCase{"painting", 0, false}};

// A case's scene prepared with the fixture's settings and its diffuse grid, and the d65 light:
// what its passes are made from. The prepared scene points at the scene and the passes at both,
// so they are made in place and never copied or moved.
struct CacheCaseInputs {
    CacheCaseInputs(const BoothSceneSetup& setup, const CacheCase& c)
        : scene(*surface::loadScene(dataDir() / "scenes" / c.scene)),
          settings(withGrid(setup.settings, c.diffuseGrid)),
          prepared(shading::prepareScene(scene, settings.horizonDirections, 0.01, setup.basis)),
          d65(shading::prepareLight(*setup.booth.find("d65-fluorescent"),
                                    setup.observer,
                                    settings.lights,
                                    setup.basis))
    {}
    CacheCaseInputs(const CacheCaseInputs&) = delete;
    CacheCaseInputs& operator=(const CacheCaseInputs&) = delete;

    static shading::RenderSettings withGrid(shading::RenderSettings s, int diffuseGrid)
    {
        s.diffuseGrid = diffuseGrid;
        return s;
    }
    const surface::SurfaceScene scene;
    const shading::RenderSettings settings;
    const shading::PreparedScene prepared;
    const shading::PreparedLight d65;
};

TEST_F(BoothCacheTest, AFrameFromTheCacheEqualsOneThatRecomputesIt)
{
    auto a = BoothScenePass::create(setup_);
    auto b = BoothScenePass::create(setup_);
    ASSERT_TRUE(a && b);
    const glm::dvec3 eye1{-0.15, 0.45, 0.60};
    const glm::dvec3 eye2{0.20, 0.40, 0.55};
    tests::StateSequence seqA, seqB;
    const auto first = draw(**a, seqA.next(0.35, eye1));
    const auto cached = draw(**a, seqA.next(0.35, eye2)); // the eye moved: only the specular term
    EXPECT_EQ((*a)->cacheRefreshes(), 1);
    const auto fresh = draw(**b, seqB.next(0.35, eye2));
    EXPECT_EQ((*b)->cacheRefreshes(), 1);
    ASSERT_EQ(cached.size(), fresh.size());
    long differ = 0;
    for (std::size_t i = 0; i < cached.size(); ++i) {
        ASSERT_EQ(cached[i], fresh[i]) << "float " << i; // bit for bit, alpha too
        differ += cached[i] != first[i] ? 1 : 0;
    }
    // The glossy surface does change with the eye (the cache is not hiding the specular term).
    EXPECT_GT(differ, kCacheW * kCacheH / 10);
}

// Light changes are the state stage's decision (SceneState::lightChanged, by the light's content
// key): the pass does not decide it again. It labels the light it holds with that key, so a state
// that says "changed" about the light it already holds redraws nothing, and one of another lamp
// is drawn with that lamp whatever lightChanged says.
TEST_F(BoothCacheTest, ThePassHoldsTheLightByItsContentKeyAndDoesNotDecideAChange)
{
    auto pass = BoothScenePass::create(setup_);
    auto fresh = BoothScenePass::create(setup_);
    ASSERT_TRUE(pass && fresh);
    const glm::dvec3 eye{0.05, 0.45, 0.60};
    tests::StateSequence seq;
    const scene::SceneState st = seq.next(0.35, eye, 2);
    const auto f0 = draw(**pass, st);
    EXPECT_EQ((*pass)->cacheRefreshes(), 1);
    scene::SceneState again = st;
    again.lightChanged = true;
    EXPECT_TRUE(tests::sameFloats(draw(**pass, again), f0));
    EXPECT_EQ((*pass)->cacheRefreshes(), 1); // the same key: nothing uploaded, nothing redrawn
    scene::SceneState other = st;
    other.lampIndex = 0;
    other.lightChanged = false;
    EXPECT_NE(scene::lightKey(other), scene::lightKey(st));
    const auto f1 = draw(**pass, other);
    EXPECT_EQ((*pass)->cacheRefreshes(), 2);
    EXPECT_TRUE(tests::sameFloats(draw(**fresh, other), f1));
    EXPECT_FALSE(tests::sameFloats(f1, f0));
}

TEST_F(BoothCacheTest, TiltNoiseIsHeldAndLightPoseAndInvalidationRefresh)
{
    auto pass = BoothScenePass::create(setup_);
    ASSERT_TRUE(pass);
    const glm::dvec3 eye{0.0, 0.45, 0.60};
    const double deg = std::numbers::pi / 180.0;
    const double tilt0 = 0.35;
    // The tilt estimator holds the diffuse term's tilt (state/tilt_estimator.h); the pass draws
    // it.
    tests::StateSequence seq;
    scene::SceneState st = seq.next(tilt0, eye);
    draw(**pass, st);
    EXPECT_EQ((*pass)->cacheRefreshes(), 1);
    EXPECT_EQ(st.heldTiltRad, tilt0);
    EXPECT_EQ(st.diffuse->shownRad, tilt0);
    // Sensor noise of +-0.25 degrees (twice the accelerometer's): the mean stays within the hold.
    std::vector<float> held;
    for (int i = 0; i < 24; ++i) {
        st = seq.next(tilt0 + (i % 2 == 0 ? 0.25 : -0.25) * deg, eye);
        held = draw(**pass, st);
    }
    EXPECT_EQ((*pass)->cacheRefreshes(), 1);
    EXPECT_EQ(st.heldTiltRad, tilt0);
    EXPECT_EQ(st.diffuse->shownRad, tilt0);
    // The held frame's cached part (alpha: E_geo) is that of the held tilt, whatever the sensed
    // one was; its specular part follows the sensed tilt.
    auto fresh = BoothScenePass::create(setup_);
    ASSERT_TRUE(fresh);
    const auto want = draw(**fresh, tests::StateSequence().next(tilt0, eye));
    ASSERT_EQ(want.size(), held.size());
    for (std::size_t i = 3; i < want.size(); i += 4) {
        ASSERT_EQ(want[i], held[i]) << "pixel " << i / 4;
    }
    // A real move of 1 degree: recomputed, and held within the hold of the new tilt.
    for (int i = 0; i < 24; ++i) {
        st = seq.next(tilt0 + 1.0 * deg, eye);
        draw(**pass, st);
    }
    const long afterMove = (*pass)->cacheRefreshes();
    EXPECT_GE(afterMove, 2);
    EXPECT_LE(std::abs(st.heldTiltRad - (tilt0 + 1.0 * deg)), state::kTiltHoldRad);
    EXPECT_EQ(st.diffuse->shownRad, st.heldTiltRad);
    // A non-finite tilt changes nothing.
    draw(**pass, seq.next(std::nan(""), eye));
    EXPECT_EQ((*pass)->cacheRefreshes(), afterMove);
    // A lamp change recomputes.
    draw(**pass, seq.next(tilt0 + 1.0 * deg, eye, 0));
    EXPECT_EQ((*pass)->cacheRefreshes(), afterMove + 1);
    // An explicit invalidation (a new channel encoding) recomputes.
    (*pass)->invalidateCache();
    draw(**pass, seq.next(tilt0 + 1.0 * deg, eye, 0));
    EXPECT_EQ((*pass)->cacheRefreshes(), afterMove + 2);
}

TEST_F(BoothCacheTest, AFreshPassDrawsAnyFrameFromItsStateAlone)
{
    // What replay relies on: two passes fed the same states draw the same frames, with the
    // cache recomputed whole or in bands over several frames, or at tilt nodes; and a fresh pass
    // given frame i's state alone (replay --from) draws frame i, a sliced refresh under way
    // included.
    for (const double nodesDeg : {0.0, 2.0}) {
        for (const int slices : {1, 3}) {
            SCOPED_TRACE(nodesDeg);
            setup_.settings.cacheSlices = slices;
            setup_.settings.tiltNodesRad = scene::degreesToRadians(nodesDeg);
            auto a = BoothScenePass::create(setup_);
            auto b = BoothScenePass::create(setup_);
            ASSERT_TRUE(a && b);
            tests::StateSequence seq(slices, {}, setup_.settings.tiltNodesRad);
            int mixed = 0;
            std::uint32_t x = 12345u;
            int refreshing = 0, alone = 0;
            for (int i = 0; i < 40; ++i) {
                x = x * 1664525u + 1013904223u; // a fixed pseudo-random walk of tilt and eye
                const double jitter = (static_cast<double>(x >> 8) / 16777216.0 - 0.5) * 0.02;
                const scene::SceneState st =
                        seq.next(0.3 + 0.004 * i + jitter, {0.01 * i, 0.45, 0.6});
                refreshing += st.diffuse->band ? 1 : 0;
                mixed += st.diffuse->mixRad ? 1 : 0;
                const auto fa = draw(**a, st);
                const auto fb = draw(**b, st);
                ASSERT_TRUE(tests::sameFloats(fa, fb))
                        << "frame " << i << ", " << slices << " slices";
                if (i % 4 == 1 || (st.diffuse->band && alone < 4)) {
                    auto fresh = BoothScenePass::create(setup_);
                    ASSERT_TRUE(fresh);
                    ASSERT_TRUE(tests::sameFloats(draw(**fresh, st), fa))
                            << "frame " << i << " drawn alone, " << slices << " slices";
                    ++alone;
                }
            }
            EXPECT_EQ((*a)->cacheRefreshes(), (*b)->cacheRefreshes());
            EXPECT_GT((*a)->cacheRefreshes(), 1);
            EXPECT_LT((*a)->cacheRefreshes(), 40);
            // With bands, some of the frames drawn alone were in the middle of a refresh (with
            // nodes a node is always drawn in bands, one band with K = 1); with nodes, most frames
            // interpolate two.
            EXPECT_EQ(refreshing > 0, slices > 1 || nodesDeg > 0.0);
            EXPECT_EQ(mixed > 20, nodesDeg > 0.0);
        }
    }
}

TEST_F(BoothCacheTest, AlphaIsTheIlluminanceOnThePanelOnEveryPixel)
{
    auto pass = BoothScenePass::create(setup_);
    ASSERT_TRUE(pass);
    const scene::SceneState st = tests::StateSequence().next(0.35, {0.0, 0.45, 0.60});
    const auto px = draw(**pass, st);
    // Independent value: eq. (1) with the macro normal over the same median-cut lights, in
    // double, at the pixel centre on the panel plane (around the surface too).
    const auto light = shading::prepareLight(*setup_.booth.find("d65-fluorescent"), setup_.observer,
                                             setup_.settings.lights, setup_.basis);
    const auto panel = scene::panelPose(setup_.stand, 0.35);
    const SurfaceLayout layout = layoutOnPanel(setup_.scene, setup_.stand);
    const booth::BoothLight& bl = *light.light;
    double worst = 0.0;
    int outside = 0;
    for (int y = 0; y < kCacheH; y += 5) {
        for (int x = 0; x < kCacheW; x += 7) {
            const double u = layout.offset.x + layout.scale.x * (x + 0.5) / kCacheW;
            const double v = layout.offset.y + layout.scale.y * (1.0 - (y + 0.5) / kCacheH);
            outside += (u < 0.0 || u > 1.0 || v < 0.0 || v > 1.0) ? 1 : 0;
            const shading::Vec3 p = panel.centre + panel.right * ((u - 0.5) * setup_.scene.widthM) +
                                    panel.up * ((0.5 - v) * setup_.scene.heightM);
            const auto irradiance = setup_.settings.areaLights ? shading::areaLightIrradiance
                                                               : shading::pointLightIrradiance;
            const double e = irradiance(light.points, bl.normal(), bl.texelAreaM2(),
                                        {p, panel.normal, panel.normal, panel.right, panel.up},
                                        nullptr, 0.0, false);
            const float got = px[(static_cast<std::size_t>(y) * kCacheW + x) * 4 + 3];
            ASSERT_GT(e, 0.0);
            worst = std::max(worst, std::abs(got - e) / e);
        }
    }
    EXPECT_GT(outside, 0); // the check covered pixels around the surface
    EXPECT_LT(worst, 1e-4);
}

// With tilt nodes the frame composes two whole terms interpolated: a frame showing (1 - w) of the
// term at 20 degrees and w of that at 22 is the two frames a pass without nodes draws at 20 and 22,
// interpolated (the specular term is the same in both and added after: linear), to float
// rounding; the nodes stay cached, so another weight between them draws no term; a node drawn in
// bands is the whole pass's, and a fresh pass asked for a frame in the middle of one draws it.
TEST_F(BoothCacheTest, ANodeFrameIsItsTwoNodesFramesInterpolated)
{
    for (const CacheCase& c : kCacheCases) {
        SCOPED_TRACE(c.scene);
        const CacheCaseInputs in(setup_, c);
        const auto& scene = in.scene;
        const auto& ps = in.prepared;
        const auto& d65 = in.d65;
        shading::RenderSettings settings = in.settings;
        auto whole = BoothShadingPass::create(ps, settings, setup_.observer);
        settings.cacheSlices = 3;
        settings.tiltNodesRad = scene::degreesToRadians(2.0);
        auto nodes = BoothShadingPass::create(ps, settings, setup_.observer);
        auto fresh = BoothShadingPass::create(ps, settings, setup_.observer);
        ASSERT_TRUE(whole && nodes && fresh);
        for (auto* pass : {&*whole, &*nodes, &*fresh}) {
            (*pass)->setSurroundIlluminance(c.surround);
            ASSERT_TRUE((*pass)->setLight(d65));
        }
        const SurfaceLayout layout = layoutOnPanel(scene, setup_.stand);
        shading::View view;
        view.panel = scene::panelPose(setup_.stand, scene::degreesToRadians(21.0));
        view.eye = {0.05, 0.45, 0.6};
        view.pixelsX = kCacheW;
        view.pixelsY = kCacheH;
        const auto pose = [&](double deg) {
            return scene::panelPose(setup_.stand, scene::degreesToRadians(deg));
        };
        const auto frame = [&](BoothShadingPass& pass, const CacheWant& want) {
            target_->bind();
            auto ok = pass.draw(view, kCacheW, kCacheH, layout, &want);
            EXPECT_TRUE(ok) << (ok ? "" : ok.error().message);
            return tests::readFloats(*target_);
        };
        const auto at = [&](double deg) { return CacheWant{pose(deg), std::nullopt}; };
        const auto between = [&](double loDeg, double hiDeg, double w) {
            return CacheWant{pose(loDeg), std::nullopt, pose(hiDeg), w};
        };
        const auto w20 = frame(**whole, at(20.0));
        const auto w22 = frame(**whole, at(22.0));
        const auto w24 = frame(**whole, at(24.0));
        const auto expectBetween = [&](const std::vector<float>& got, const std::vector<float>& a,
                                       const std::vector<float>& b, double w) {
            ASSERT_EQ(got.size(), a.size());
            double worst = 0.0;
            long differ = 0;
            for (std::size_t i = 0; i < got.size(); ++i) {
                const double want = (1.0 - w) * a[i] + w * b[i];
                worst = std::max(worst, std::abs(got[i] - want) / std::max(std::abs(want), 1e-3));
                differ += a[i] != b[i] ? 1 : 0;
            }
            EXPECT_LT(worst, 1e-5);
            EXPECT_GT(differ, static_cast<long>(got.size()) / 4); // the two nodes differ
        };
        BoothShadingPass& n = **nodes;
        expectBetween(frame(n, between(20.0, 22.0, 0.25)), w20, w22, 0.25);
        EXPECT_EQ(n.cacheRefreshes(), 2); // both drawn whole: the first frame
        expectBetween(frame(n, between(20.0, 22.0, 0.75)), w20, w22, 0.75);
        EXPECT_TRUE(tests::sameFloats(frame(n, at(22.0)), w22)); // a node alone: its own frame
        EXPECT_EQ(n.cacheRefreshes(), 2);                        // held: nothing drawn
        // 24 drawn in three bands while the frames interpolate 20 and 22; then 22 and 24.
        for (int b = 0; b < 3; ++b) {
            CacheWant want = between(20.0, 22.0, 0.5);
            want.band = CacheBand{pose(24.0), b, 3};
            expectBetween(frame(n, want), w20, w22, 0.5);
        }
        EXPECT_EQ(n.cacheRefreshes(), 3);
        EXPECT_FALSE(n.cacheRefreshPending());
        expectBetween(frame(n, between(22.0, 24.0, 0.5)), w22, w24, 0.5);
        EXPECT_TRUE(tests::sameFloats(frame(n, at(24.0)), w24)); // banded: the whole pass's
        EXPECT_EQ(n.cacheRefreshes(), 3);
        // A fresh pass asked for the middle band: the two shown whole, the earlier band first.
        CacheWant middle = between(20.0, 22.0, 0.5);
        middle.band = CacheBand{pose(24.0), 1, 3};
        expectBetween(frame(**fresh, middle), w20, w22, 0.5);
        EXPECT_TRUE((*fresh)->cacheRefreshPending());
        middle.band->band = 2;
        expectBetween(frame(**fresh, middle), w20, w22, 0.5);
        EXPECT_FALSE((*fresh)->cacheRefreshPending());
        EXPECT_TRUE(tests::sameFloats(frame(**fresh, at(24.0)), w24));
        EXPECT_EQ((*fresh)->cacheRefreshes(), 3);
    }
}

// A tilt's recompute in K = 3 bands over three draws, each band the one the frame names (the
// state stage decides them: pipeline/scene/diffuse_schedule.h): each frame composes from one whole
// cache, the one a pass that recomputes at once draws for the tilt shown; the last band's frame
// is the unsliced pass's at the new tilt, bit for bit; a band asked for without the earlier ones
// (frame N drawn alone) draws them first; a new light or layout draws the term shown whole. On
// both kCacheCases.
TEST_F(BoothCacheTest, TheBandTheFrameNamesIsDrawnAndTheLastShowsTheUnslicedFrame)
{
    for (const CacheCase& c : kCacheCases) {
        SCOPED_TRACE(c.scene);
        const CacheCaseInputs in(setup_, c);
        const auto& scene = in.scene;
        const auto& ps = in.prepared;
        const auto& d65 = in.d65;
        shading::RenderSettings settings = in.settings;
        const auto tungsten = shading::prepareLight(*setup_.booth.find("tungsten"), setup_.observer,
                                                    settings.lights, setup_.basis);
        auto whole = BoothShadingPass::create(ps, settings, setup_.observer);
        settings.cacheSlices = 3;
        auto sliced = BoothShadingPass::create(ps, settings, setup_.observer);
        ASSERT_TRUE(whole && sliced);
        for (auto* pass : {&*whole, &*sliced}) {
            (*pass)->setSurroundIlluminance(c.surround);
            ASSERT_TRUE((*pass)->setLight(d65));
        }
        SurfaceLayout layout = layoutOnPanel(scene, setup_.stand);
        shading::View view; // the specular term's pose and eye stay put: only the cache moves
        view.panel = scene::panelPose(setup_.stand, scene::degreesToRadians(20.0));
        view.eye = {0.05, 0.45, 0.6};
        view.pixelsX = kCacheW;
        view.pixelsY = kCacheH;
        const auto pose = [&](double deg) {
            return scene::panelPose(setup_.stand, scene::degreesToRadians(deg));
        };
        // The frame showing the term at shownDeg and, given, drawing band b of 3 toward towardDeg.
        const auto frame = [&](BoothShadingPass& pass, double shownDeg, double towardDeg = 0.0,
                               int b = -1) {
            CacheWant want{pose(shownDeg), std::nullopt};
            if (b >= 0) {
                want.band = CacheBand{pose(towardDeg), b, 3};
            }
            target_->bind();
            auto ok = pass.draw(view, kCacheW, kCacheH, layout, &want);
            EXPECT_TRUE(ok) << (ok ? "" : ok.error().message);
            return tests::readFloats(*target_);
        };
        // The unsliced pass's frames with the cache at 20, 23 and 27 degrees (recomputed whole).
        const auto w20 = frame(**whole, 20.0);
        const auto w23 = frame(**whole, 23.0);
        const auto w27 = frame(**whole, 27.0);
        long moved = 0;
        for (std::size_t i = 0; i < w20.size(); ++i) {
            moved += w20[i] != w23[i] ? 1 : 0;
        }
        EXPECT_GT(moved, kCacheW * kCacheH / 2); // the cache's pose shows in the frame
        BoothShadingPass& s = **sliced;
        EXPECT_TRUE(tests::sameFloats(frame(s, 20.0), w20)); // the first cache is drawn whole
        EXPECT_EQ(s.cacheRefreshes(), 1);
        EXPECT_FALSE(s.cacheRefreshPending());
        EXPECT_TRUE(tests::sameFloats(frame(s, 20.0, 23.0, 0), w20)); // band 1 of 3 behind it
        EXPECT_TRUE(s.cacheRefreshPending());
        EXPECT_TRUE(tests::sameFloats(frame(s, 20.0, 23.0, 1), w20)); // band 2
        EXPECT_TRUE(tests::sameFloats(frame(s, 23.0, 23.0, 2), w23)); // band 3 shows 23
        EXPECT_EQ(s.cacheRefreshes(), 2);
        EXPECT_FALSE(s.cacheRefreshPending());
        EXPECT_TRUE(tests::sameFloats(frame(s, 23.0, 27.0, 0), w23));
        EXPECT_TRUE(tests::sameFloats(frame(s, 23.0, 27.0, 1), w23));
        EXPECT_TRUE(tests::sameFloats(frame(s, 27.0, 27.0, 2), w27)); // the unsliced frame
        EXPECT_TRUE(tests::sameFloats(frame(s, 27.0), w27));          // held: nothing drawn
        EXPECT_EQ(s.cacheRefreshes(), 3);
        EXPECT_FALSE(s.cacheRefreshPending());
        // Band 2 asked for by a fresh pass (frame N drawn alone): the term shown whole and bands
        // 1 and 2 drawn first; the next frame's last band then completes the refresh.
        auto alone = BoothShadingPass::create(ps, settings, setup_.observer);
        ASSERT_TRUE(alone);
        (*alone)->setSurroundIlluminance(c.surround);
        ASSERT_TRUE((*alone)->setLight(d65));
        EXPECT_TRUE(tests::sameFloats(frame(**alone, 20.0, 23.0, 1), w20));
        EXPECT_TRUE((*alone)->cacheRefreshPending());
        EXPECT_TRUE(tests::sameFloats(frame(**alone, 23.0, 23.0, 2), w23));
        EXPECT_EQ((*alone)->cacheRefreshes(), 2);
        // A new light in the middle of a refresh: the term shown drawn whole at once.
        EXPECT_TRUE(tests::sameFloats(frame(s, 27.0, 20.0, 0), w27));
        EXPECT_TRUE(s.cacheRefreshPending());
        ASSERT_TRUE((*whole)->setLight(tungsten));
        ASSERT_TRUE(s.setLight(tungsten));
        const auto t23 = frame(**whole, 23.0);
        EXPECT_TRUE(tests::sameFloats(frame(s, 23.0), t23));
        EXPECT_FALSE(s.cacheRefreshPending());
        EXPECT_FALSE(tests::sameFloats(t23, w23));
        // A new layout in the middle of a refresh: the term shown drawn whole again (the compose
        // places the surface by the new one, and the facet normals follow it), the bands so far
        // after it; the last band completes the refresh at the new layout.
        EXPECT_TRUE(tests::sameFloats(frame(s, 23.0, 27.0, 0), t23));
        EXPECT_TRUE(s.cacheRefreshPending());
        layout.offset.x += 0.125;
        const auto moved23 = frame(**whole, 23.0);
        const auto moved27 = frame(**whole, 27.0);
        EXPECT_TRUE(tests::sameFloats(frame(s, 23.0, 27.0, 1), moved23));
        EXPECT_TRUE(tests::sameFloats(frame(s, 27.0, 27.0, 2), moved27));
        EXPECT_FALSE(s.cacheRefreshPending());
        EXPECT_FALSE(tests::sameFloats(moved27, moved23));
    }
}

TEST_F(BoothCacheTest, WithoutTheSurroundOnlyTheSurfaceRectangleIsShaded)
{
    auto with = BoothScenePass::create(setup_);
    auto without = BoothScenePass::create(setup_);
    ASSERT_TRUE(with && without);
    EXPECT_TRUE((*with)->surroundIlluminance()); // the default
    (*without)->setSurroundIlluminance(false);
    const PixelRect r = (*with)->surfaceRect(kCacheW, kCacheH);
    ASSERT_GT(r.width, 0);
    ASSERT_LT(r.width * r.height, kCacheW * kCacheH); // the surface does not fill the panel
    tests::StateSequence seq;
    for (const double tilt : {0.35, 0.6}) { // the second recomputes the cache
        const auto st = seq.next(tilt, {0.1, 0.5, 0.5});
        const auto a = draw(**with, st);
        const auto b = draw(**without, st);
        long inside = 0, outsideLit = 0;
        for (int y = 0; y < kCacheH; ++y) {
            for (int x = 0; x < kCacheW; ++x) {
                const std::size_t i = (static_cast<std::size_t>(y) * kCacheW + x) * 4;
                const bool in = x >= r.x && x < r.x + r.width && y >= r.y && y < r.y + r.height;
                if (in) {
                    ++inside;
                    for (int c = 0; c < 4; ++c) {
                        ASSERT_EQ(a[i + c], b[i + c]) << x << ", " << y << " channel " << c;
                    }
                } else {
                    for (int c = 0; c < 3; ++c) {
                        ASSERT_EQ(a[i + c], 0.0f); // the black panel either way
                        ASSERT_EQ(b[i + c], 0.0f);
                    }
                    ASSERT_EQ(b[i + 3], 0.0f); // no illuminance where nothing reads it
                    outsideLit += a[i + 3] > 0.0f ? 1 : 0;
                }
            }
        }
        EXPECT_EQ(inside, static_cast<long>(r.width) * r.height);
        EXPECT_GT(outsideLit, 0); // with it, E_geo is there around the surface
    }
    EXPECT_EQ((*without)->cacheRefreshes(), 2);
    // Turning it back on recomputes the cache (it was drawn without the surround).
    (*without)->setSurroundIlluminance(true);
    const auto st = seq.next(0.6, {0.1, 0.5, 0.5});
    EXPECT_EQ(draw(**with, st), draw(**without, st));
    EXPECT_EQ((*without)->cacheRefreshes(), 3);
    // And off again: the cache held E_geo around the surface, so it is cleared there once more
    // (between refreshes without the surround it is not cleared: mode 0 never writes there).
    (*without)->setSurroundIlluminance(false);
    const auto off = draw(**without, st);
    EXPECT_EQ((*without)->cacheRefreshes(), 4);
    for (int y = 0; y < kCacheH; ++y) {
        for (int x = 0; x < kCacheW; ++x) {
            if (!(x >= r.x && x < r.x + r.width && y >= r.y && y < r.y + r.height)) {
                ASSERT_EQ(off[(static_cast<std::size_t>(y) * kCacheW + x) * 4 + 3], 0.0f)
                        << x << ", " << y;
            }
        }
    }
}

} // namespace
} // namespace replica::pipeline::render
