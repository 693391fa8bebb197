// The exact reference against closed forms (Lambert's polygon formula, a point source), and the
// real-time model against the reference, including the hard cases that must never produce NaN/Inf.
#include <algorithm>
#include <cmath>

#include <glm/geometric.hpp>

#include <pipeline/base/data_dir.h>
#include <pipeline/booth/booth_model.h>
#include <pipeline/colour/cielab.h>
#include <pipeline/reference/frame_error.h>
#include <pipeline/reference/reference_integrator.h>
#include <pipeline/shading/realtime_model.h>
#include <pipeline/spectral/adaptive_encoding.h>
#include <pipeline/surface/surface_scene.h>

#include <gtest/gtest.h>

#include "render_fixtures.h"

namespace replica::pipeline {
namespace {

using reference::Vec3;

// The shipped painting and booth, and the view where the ceiling grazes the panel (10-degree
// tilt, 32 x 20): what the relief-horizon tests below share, loaded once.
struct GrazingPainting {
    surface::SurfaceScene scene;
    booth::Booth booth;
    shading::View view;
    const booth::BoothLight& light(const std::string& name) const
    {
        for (const auto& l : booth.lights) {
            if (l.name == name) {
                return l;
            }
        }
        ADD_FAILURE() << "no booth light named " << name;
        return booth.lights.front();
    }
};

const GrazingPainting& grazingPainting()
{
    static const GrazingPainting g = [] {
        auto scene = surface::loadScene(dataDir() / "scenes" / "painting");
        auto booth = booth::loadBooth(dataDir() / "booth");
        EXPECT_TRUE(scene && booth);
        GrazingPainting out{*scene, *booth, {}};
        out.view.panel = scene::panelPose(scene::degreesToRadians(10.0));
        out.view.pixelsX = 32;
        out.view.pixelsY = 20;
        return out;
    }();
    return g;
}

std::vector<Vec3> corners(const booth::BoothLight& l)
{
    return {l.pointAtTexel(0, 0), l.pointAtTexel(l.luminance.width, 0),
            l.pointAtTexel(l.luminance.width, l.luminance.height),
            l.pointAtTexel(0, l.luminance.height)};
}

TEST(ReferenceIrradiance, UniformEmitterMatchesLambertsPolygonFormula)
{
    const booth::BoothLight light = test::ceilingLight(200, 100, 1000.0, 0.5);
    const auto cloud = reference::texelCloud(light);
    for (const Vec3& n :
         {Vec3(0, 1, 0), glm::normalize(Vec3(0, 1, 0.4)), glm::normalize(Vec3(0.3, 1, -0.2))}) {
        for (const Vec3& p : {Vec3(0, 0, 0), Vec3(0.2, 0.1, -0.1), Vec3(-0.4, 0.25, 0.2)}) {
            const double exact = reference::polygonIrradiance(corners(light), p, n, 1000.0);
            const auto sums =
                    reference::integrateTexels(cloud, p, n, n, n, brdf::WardModel::WardDur, 0.1,
                                               false, nullptr, Vec3(1, 0, 0), Vec3(0, 0, -1));
            EXPECT_NEAR(sums.irradiance, exact, 1e-3 * exact) << p.x << " " << p.y;
        }
    }
    // A point just under the middle of a large emitter sees almost a hemisphere: E -> pi L.
    const booth::BoothLight big = test::ceilingLight(64, 64, 1000.0, 0.5, 50.0, 50.0);
    const double e =
            reference::polygonIrradiance(corners(big), Vec3(0, 0.499, 0), Vec3(0, 1, 0), 1000.0);
    EXPECT_NEAR(e, M_PI * 1000.0, 1e-3 * M_PI * 1000.0);
}

TEST(ReferenceIrradiance, PointTouchingTheEmitterStaysBounded)
{
    const booth::BoothLight light = test::ceilingLight(100, 50, 1000.0, 0.5);
    const auto cloud = reference::texelCloud(light);
    for (double gap : {1e-3, 1e-6, 0.0}) {
        const Vec3 p(0.0, 0.5 - gap, 0.0);
        const Vec3 n(0, 1, 0);
        const auto s = reference::integrateTexels(cloud, p, n, n, n, brdf::WardModel::WardDur, 0.1,
                                                  true, nullptr, Vec3(1, 0, 0), Vec3(0, 0, -1));
        EXPECT_TRUE(std::isfinite(s.irradiance) && std::isfinite(s.specular));
        EXPECT_LE(s.irradiance, 1.05 * M_PI * 1000.0) << gap;
    }
}

TEST(PointLights, HotTexelEqualsThePointSourceFormula)
{
    booth::BoothLight light = test::ceilingLight(64, 32, 0.0, 0.6);
    light.luminance.at(40, 11) = 2.0e6;
    const auto prepared = shading::prepareLight(light, test::observer(), 32);
    const Vec3 q = light.pointAtTexel(40.5, 11.5);
    const Vec3 p(0.05, 0.1, 0.03);
    const Vec3 n = glm::normalize(Vec3(0.1, 1.0, 0.3));
    const Vec3 d = q - p;
    const double d2 = glm::dot(d, d);
    const Vec3 i = d / std::sqrt(d2);
    const double expected =
            2.0e6 * light.texelAreaM2() * glm::dot(n, i) * glm::dot(light.normal(), -i) / d2;
    const double e =
            shading::pointLightIrradiance(prepared.points, light.normal(), light.texelAreaM2(),
                                          {p, n, n, Vec3(1, 0, 0), Vec3(0, 0, -1)});
    EXPECT_NEAR(e, expected, 1e-9 * expected);
    // The point light's intensity is L * a of the texel: the one whose region holds the hot texel
    // carries at least it.
    double hottest = 0.0;
    for (const auto& l : prepared.points) {
        EXPECT_NEAR(l.intensityCd, l.sumCdM2 * light.texelAreaM2(), 1e-12 * l.intensityCd);
        hottest = std::max(hottest, l.intensityCd);
    }
    EXPECT_GE(hottest, 2.0e6 * light.texelAreaM2());
    const auto ref = reference::integrateTexels(reference::texelCloud(light), p, n, n, n,
                                                brdf::WardModel::WardDur, 0.1, false, nullptr,
                                                Vec3(1, 0, 0), Vec3(0, 0, -1));
    EXPECT_NEAR(ref.irradiance, expected, 1e-9 * expected);
}

TEST(PointLights, SpreadIsTheRegionsStandardDeviationAlongEachEdge)
{
    // One region over a uniform 12 x 6 image of a 1.0 x 0.5 m ceiling: a uniform box of width W
    // has standard deviation W / sqrt(12), along edgeU and edgeV.
    booth::BoothLight light = test::ceilingLight(12, 6, 500.0);
    const booth::RegionLight all{500.0 * 72, 6.0, 3.0, 0, 0, 12, 6};
    auto points = booth::pointLights(light, {all});
    ASSERT_EQ(points.size(), 1u);
    EXPECT_NEAR(points[0].spreadU.x, 1.0 / std::sqrt(12.0), 1e-12);
    EXPECT_NEAR(points[0].spreadV.z, 0.5 / std::sqrt(12.0), 1e-12);
    EXPECT_EQ(points[0].spreadU.y, 0.0);
    EXPECT_EQ(points[0].spreadV.x, 0.0);
    // A hot texel inside a dark region: the spread of that texel alone, wherever the region ends.
    light.luminance = booth::LuminanceImage::filled(12, 6, 0.0);
    light.luminance.at(7, 2) = 1e6;
    points = booth::pointLights(light, {booth::RegionLight{1e6, 7.5, 2.5, 4, 0, 12, 6}});
    EXPECT_NEAR(glm::length(points[0].spreadU), (1.0 / 12) / std::sqrt(12.0), 1e-12);
    EXPECT_NEAR(glm::length(points[0].spreadV), (0.5 / 6) / std::sqrt(12.0), 1e-12);
    // A dark region has no spread (and no light).
    points = booth::pointLights(light, {booth::RegionLight{0.0, 1.0, 4.0, 0, 3, 2, 6}});
    EXPECT_EQ(glm::length(points[0].spreadU), 0.0);
    EXPECT_EQ(glm::length(points[0].spreadV), 0.0);
}

TEST(PointLights, ThirtyTwoLightsAreWithinTheMeasuredErrorOfTheReference)
{
    // rendering-background.md 2.4: striped emitter 0.5 m above, VM 32 lights: about 0.6 % mean, < 1
    // % max when the plane faces the light.
    const booth::BoothLight light = test::stripedLight(160, 80, 0.5);
    const auto prepared = shading::prepareLight(light, test::observer(), 32);
    const auto cloud = reference::texelCloud(light);
    double sumErr = 0.0, maxErr = 0.0;
    int count = 0;
    const Vec3 n(0, 1, 0);
    for (int a = 0; a < 9; ++a) {
        for (int b = 0; b < 7; ++b) {
            const Vec3 p(-0.2 + 0.05 * a, 0.0, -0.15 + 0.05 * b);
            const double e = shading::pointLightIrradiance(
                    prepared.points, light.normal(), light.texelAreaM2(),
                    {p, n, n, Vec3(1, 0, 0), Vec3(0, 0, -1)});
            const double r =
                    reference::integrateTexels(cloud, p, n, n, n, brdf::WardModel::WardDur, 0.1,
                                               false, nullptr, Vec3(1, 0, 0), Vec3(0, 0, -1))
                            .irradiance;
            const double err = std::abs(e / r - 1.0);
            sumErr += err;
            maxErr = std::max(maxErr, err);
            ++count;
        }
    }
    EXPECT_LT(sumErr / count, 0.008);
    EXPECT_LT(maxErr, 0.015);
}

struct Case {
    surface::SurfaceScene scene;
    booth::BoothLight light;
    shading::View view;
};

Case setup(bool bumpy, bool glossy, double tiltDeg, int px = 24, int py = 16)
{
    Case s{test::testScene(48, 32, bumpy, glossy), test::stripedLight(64, 32, 0.6), {}};
    s.view.panel = scene::panelPose(scene::degreesToRadians(tiltDeg));
    s.view.pixelsX = px;
    s.view.pixelsY = py;
    return s;
}

// A case rendered by the exact reference and by the model at 'settings' (128 point lights unless
// the caller says otherwise), with what the model was prepared from, for renders with a knob
// changed. 's' must outlive it (the prepared scene and light point into it).
struct Compared {
    shading::XyzFrame ref;
    shading::PreparedScene ps;
    shading::PreparedLight pl;
    shading::XyzFrame fast;
    reference::FrameError err;
};

Compared renderBoth(const Case& s, int horizonDirections, const shading::RenderSettings& settings)
{
    Compared c;
    c.ref = reference::renderReference(s.scene, s.light, s.view, test::observer());
    c.ps = shading::prepareScene(s.scene, horizonDirections);
    c.pl = shading::prepareLight(s.light, test::observer(), settings.lights);
    c.fast = shading::renderRealtime(c.ps, c.pl, s.view, test::observer(), settings);
    c.err = reference::compareFrames(c.ref, c.fast);
    return c;
}

void expectAllFinite(const shading::XyzFrame& f)
{
    EXPECT_EQ(f.nonFinite, 0);
    for (const auto& v : f.xyz) {
        ASSERT_TRUE(std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z));
        ASSERT_GE(v.y, 0.0);
    }
}

TEST(RealtimeModel, FlatGlossySceneIsCloseToTheReference)
{
    Case s = setup(false, true, 40.0);
    shading::RenderSettings settings;
    settings.lights = 128;
    settings.specularSamples = 32;
    const auto [ref, ps, pl, fast, err] = renderBoth(s, 8, settings);
    expectAllFinite(ref);
    expectAllFinite(fast);
    EXPECT_LT(err.p95, 1.0);
    EXPECT_LT(err.max, 3.0);
    // A specular highlight exists at this tilt: the frame is not just the diffuse term.
    const auto matte = shading::renderRealtime(ps, pl, s.view, test::observer(), [&] {
        auto m = settings;
        m.specularPass = false;
        return m;
    }());
    double diff = 0.0;
    for (std::size_t k = 0; k < fast.xyz.size(); ++k) {
        diff = std::max(diff, fast.xyz[k].y - matte.xyz[k].y);
    }
    EXPECT_GT(diff, 0.0);
}

TEST(RealtimeModel, BumpySceneWithShadowsIsCloseToTheReference)
{
    Case s = setup(true, false, 30.0);
    shading::RenderSettings settings;
    settings.lights = 128;
    const auto [ref, ps, pl, fast, err] = renderBoth(s, 16, settings);
    expectAllFinite(fast);
    EXPECT_LT(err.mean, 1.0);
    // And the relief matters: ignoring it is clearly worse.
    settings.reliefPass = false;
    const auto noRelief = shading::renderRealtime(ps, pl, s.view, test::observer(), settings);
    EXPECT_GT(reference::compareFrames(ref, noRelief).mean, err.mean);
}

TEST(RealtimeModel, GrazingCeilingSpreadsEachLightsHorizonOverItsRegion)
{
    // The shipped painting at a 10-degree tilt: the ceiling grazes the panel and the relief's
    // horizons cut through the regions the 32 point lights stand for. A sharp horizon test per
    // point turns a region all dark or all lit where the reference sees part of it; each light's
    // horizon spread over its region's extent (booth::PointLight::spreadU/V) must do better.
    const GrazingPainting& g = grazingPainting();
    const surface::SurfaceScene* scene = &g.scene;
    const booth::BoothLight* light = &g.light("d50-fluorescent");
    const shading::View& view = g.view;
    const auto ref = reference::renderReference(*scene, *light, view, test::observer());
    shading::RenderSettings settings;
    settings.specularSamples = shading::defaultSpecularSamples(*scene);
    const auto ps = shading::prepareScene(*scene, settings.horizonDirections);
    auto pl = shading::prepareLight(*light, test::observer(), settings.lights);
    const auto spread = shading::renderRealtime(ps, pl, view, test::observer(), settings);
    for (auto& p : pl.points) {
        EXPECT_GT(glm::length(p.spreadU) + glm::length(p.spreadV), 0.0);
        p.spreadU = Vec3(0.0);
        p.spreadV = Vec3(0.0);
    }
    const auto sharp = shading::renderRealtime(ps, pl, view, test::observer(), settings);
    const auto withSpread = reference::compareFrames(ref, spread);
    const auto withoutSpread = reference::compareFrames(ref, sharp);
    // With each texel's own horizon (render profile 1) the spread took this 32 x 20 frame's max
    // from 4.63 to 4.41 (64 x 40: 4.72 -> 3.07). With eq. (1)'s horizon read bilinearly, as the
    // model now always does, the spread moves this frame by less than 0.01 ΔE00 either way
    // (measured: p95 3.7068 against 3.7062, mean 3.1782 against 3.1773): it is kept for the
    // regions that straddle a horizon, and must cost nothing measurable here.
    EXPECT_LE(withSpread.max, withoutSpread.max + 0.01)
            << "max " << withSpread.max << " against " << withoutSpread.max;
    EXPECT_LE(withSpread.p95, withoutSpread.p95 + 0.01);
    EXPECT_LE(withSpread.mean, withoutSpread.mean + 0.01);
}

TEST(RealtimeModel, BilinearHorizonsKeepTheGrazingPaintingWithinBudget)
{
    // The shipped painting at a 10-degree tilt in the appliance's adaptive channels: with each
    // texel's own horizon the worst pixels were far off (a light's visibility turns within a
    // texel when the ceiling grazes the panel); read bilinearly at the pixel's point, as the
    // reference marches from that point, they are within the budget. Measured on this 32 x 20
    // frame: max 2.42 with the texel's horizon, 0.95 bilinear (64 x 40: 3.07 -> 1.51; 96 x 60:
    // 3.35 -> 1.58).
    const GrazingPainting& g = grazingPainting();
    const surface::SurfaceScene* scene = &g.scene;
    const booth::BoothLight* light = &g.light("d50-fluorescent");
    const shading::View& view = g.view;
    auto encoder = spectral::AdaptiveEncoder::createDefault(dataDir());
    ASSERT_TRUE(encoder);
    auto basis = encoder->basisFor(light->spd);
    ASSERT_TRUE(basis) << basis.error().message;
    const auto ref = reference::renderReference(*scene, *light, view, test::observer());
    shading::RenderSettings settings;
    settings.specularSamples = shading::defaultSpecularSamples(*scene);
    const auto ps = shading::prepareScene(*scene, settings.horizonDirections, 0.01, *basis);
    const auto pl = shading::prepareLight(*light, test::observer(), settings.lights, *basis);
    const auto bilinear = reference::compareFrames(
            ref, shading::renderRealtime(ps, pl, view, test::observer(), settings));
    EXPECT_LT(bilinear.max, 1.5) << "p95 " << bilinear.p95;
}

TEST(RealtimeModel, HalfHorizonsMoveTheFrameByLittle)
{
    // The model reads the horizon map rounded to half floats (PreparedScene::horizonHalf, what
    // the GL pass packs): within a hundredth of ΔE00 of the float map's frame (a sine moves by
    // 2^-12 at most, against a smoothstep 0.04 wide; measured: max 0.0008), and not the same
    // frame (the rounding reaches it).
    const GrazingPainting& g = grazingPainting();
    const surface::SurfaceScene* scene = &g.scene;
    const booth::BoothLight& light = g.booth.lights.front();
    const shading::View& view = g.view;
    shading::RenderSettings settings;
    settings.specularSamples = shading::defaultSpecularSamples(*scene);
    auto ps = shading::prepareScene(*scene, settings.horizonDirections);
    const auto pl = shading::prepareLight(light, test::observer(), settings.lights);
    const auto half = shading::renderRealtime(ps, pl, view, test::observer(), settings);
    ps.horizonHalf = ps.horizon; // the float sines in the model's place
    const auto full = shading::renderRealtime(ps, pl, view, test::observer(), settings);
    ASSERT_EQ(half.xyz.size(), full.xyz.size());
    std::size_t moved = 0;
    for (std::size_t i = 0; i < half.xyz.size(); ++i) {
        moved += half.xyz[i] != full.xyz[i] ? 1 : 0;
    }
    EXPECT_GT(moved, 0u);
    const auto e = reference::compareFrames(full, half);
    EXPECT_LT(e.max, 0.01) << "mean " << e.mean << " p95 " << e.p95;
}

TEST(RealtimeModel, BumpyGlossySceneWithShadowsIsCloseToTheReference)
{
    // The reference tests every texel's direction against the horizon; the model shadows each
    // specular lobe with the horizon at its mirror direction's azimuth (realtime_model.cpp).
    // Relief four times the other tests' (slopes near 1) and the panel tilted to 60 degrees, so
    // that the ceiling's light and its reflections graze the bumps.
    Case s = setup(true, true, 60.0);
    for (double& h : s.scene.relief.m) {
        h *= 4.0;
    }
    shading::RenderSettings settings;
    settings.lights = 128;
    const auto [ref, ps, pl, fast, err] = renderBoth(s, 8, settings);
    expectAllFinite(fast);
    EXPECT_LT(err.p95, 1.0); // measured 0.34 (0.42 with each texel's own horizon)
    EXPECT_LT(err.max, 3.0); // measured 0.63 (0.94)
    // The horizons shadow here, as much as the reference's do: taking them away adds light, and
    // the frame's Y summed is nearer the reference's with them than without. Point lights
    // (measured: 72216 and 72283 against 72207; each texel's own horizon, 72091, overshot the
    // other way): much nearer. Area lights (72178 and 72246): nearer, each region's one horizon
    // test along its centroid taking a little too much (0.04 %) where the open frame is 0.05 %
    // over.
    for (const bool area : {false, true}) {
        shading::RenderSettings shadowed = settings;
        shadowed.areaLights = area;
        shading::RenderSettings openSettings = shadowed;
        openSettings.horizonDirections = 0;
        const auto withHorizon =
                shading::renderRealtime(ps, pl, s.view, test::observer(), shadowed);
        const auto open = shading::renderRealtime(ps, pl, s.view, test::observer(), openSettings);
        double shadowedY = 0.0, openY = 0.0, refY = 0.0;
        for (std::size_t k = 0; k < fast.xyz.size(); ++k) {
            shadowedY += withHorizon.xyz[k].y;
            openY += open.xyz[k].y;
            refY += ref.xyz[k].y;
        }
        EXPECT_LT(shadowedY, openY);
        EXPECT_LT(std::abs(shadowedY - refY), (area ? 0.9 : 0.25) * std::abs(openY - refY))
                << "shadowed " << shadowedY << ", open " << openY << ", reference " << refY;
        EXPECT_LT(std::abs(shadowedY / refY - 1.0), 5e-4) << area;
    }
}

TEST(RealtimeModel, SpecularLobeIsShadowedByTheHorizonAtItsMirrorAzimuth)
{
    const booth::BoothLight light = test::ceilingLight(16, 8, 1000.0);
    const auto pl = shading::prepareLight(light, test::observer(), 32);
    // A point below the ceiling facing up (tangent x = booth x, tangent y = booth -z); the eye
    // low towards -x, so the mirror direction climbs at 60 degrees towards +x: azimuth 0.
    const Vec3 p(0.0, 0.0, 0.0), n(0.0, 1.0, 0.0), right(1.0, 0.0, 0.0), up(0.0, 0.0, -1.0);
    const Vec3 toEye = glm::normalize(Vec3(-0.2, 0.35, 0.0));
    surface::HorizonMap map;
    map.width = map.height = 1;
    map.directions = 8;
    const auto specular = [&](const surface::HorizonMap* h) {
        return shading::filteredSpecular(pl, {p, n, n, right, up}, toEye,
                                         brdf::WardModel::WardDurGuarded, 0.1, 48, h, 0.02,
                                         shading::kDefaultSpecularLodBias, true);
    };
    const double unshadowed = specular(nullptr);
    ASSERT_GT(unshadowed, 0.0);
    map.sinBeta.assign(8, 0.0f); // open all round
    EXPECT_EQ(specular(&map), unshadowed);
    // A wall all but vertical on the mirror's side (azimuths -45..45 degrees): only the lobe's
    // tail nearest the normal clears it (measured 0.4%).
    map.sinBeta = {0.999f, 0.999f, 0.0f, 0.0f, 0.0f, 0.0f, 0.0f, 0.999f};
    EXPECT_LT(specular(&map), 0.01 * unshadowed);
    // The same wall behind the viewer's side shadows nothing of it.
    map.sinBeta = {0.0f, 0.0f, 0.0f, 0.999f, 0.999f, 0.999f, 0.0f, 0.0f};
    EXPECT_EQ(specular(&map), unshadowed);
    // A wall at the lobe's own elevation (sin 60 degrees) cuts off its lower half, about.
    map.sinBeta = {0.866f, 0.866f, 0.0f, 0.0f, 0.0f, 0.0f, 0.0f, 0.866f};
    const double half = specular(&map);
    EXPECT_GT(half, 0.25 * unshadowed);
    EXPECT_LT(half, 0.75 * unshadowed);
}

TEST(RealtimeModel, FlatHeightFieldIsBitIdenticalWithAndWithoutReliefPasses)
{
    Case s = setup(false, true, 40.0);
    for (double& h : s.scene.relief.m) {
        h = 0.003; // constant offset: flat
    }
    const auto ps = shading::prepareScene(s.scene, 8);
    const auto pl = shading::prepareLight(s.light, test::observer(), 32);
    shading::RenderSettings on;
    shading::RenderSettings off = on;
    off.reliefPass = false;
    off.horizonDirections = 0;
    const auto a = shading::renderRealtime(ps, pl, s.view, test::observer(), on);
    const auto b = shading::renderRealtime(ps, pl, s.view, test::observer(), off);
    ASSERT_EQ(a.xyz.size(), b.xyz.size());
    for (std::size_t k = 0; k < a.xyz.size(); ++k) {
        ASSERT_EQ(a.xyz[k], b.xyz[k]);
    }
}

TEST(RealtimeModel, SameInputsGiveBitIdenticalFramesWithOneOrTwoThreads)
{
    Case s = setup(true, true, 40.0);
    const auto ps = shading::prepareScene(s.scene, 8);
    const auto pl = shading::prepareLight(s.light, test::observer(), 32);
    shading::RenderSettings one;
    one.threads = 1;
    shading::RenderSettings two;
    two.threads = 2;
    const auto a = shading::renderRealtime(ps, pl, s.view, test::observer(), one);
    const auto b = shading::renderRealtime(ps, pl, s.view, test::observer(), two);
    for (std::size_t k = 0; k < a.xyz.size(); ++k) {
        ASSERT_EQ(a.xyz[k], b.xyz[k]);
    }
}

TEST(RenderHardCases, LightBehindTheSurfaceGivesExactlyZero)
{
    // Tilted face-down: the ceiling is behind the panel, so diffuse, specular and flare are all 0.
    Case s = setup(true, true, -90.0);
    const auto ref = reference::renderReference(s.scene, s.light, s.view, test::observer());
    const auto ps = shading::prepareScene(s.scene, 8);
    const auto pl = shading::prepareLight(s.light, test::observer(), 32);
    s.view.eye = Vec3(0.0, -0.5, 0.3);
    const auto fast =
            shading::renderRealtime(ps, pl, s.view, test::observer(), shading::RenderSettings{});
    for (const auto* f : {&ref, &fast}) {
        expectAllFinite(*f);
        for (const auto& v : f->xyz) {
            ASSERT_EQ(v, colour::Xyz(0.0));
        }
    }
}

TEST(RenderHardCases, EyeInOrBehindTheScreenPlaneDropsSpecularAndFlagsTheFrame)
{
    Case s = setup(false, true, 40.0);
    const auto ps = shading::prepareScene(s.scene, 8);
    const auto pl = shading::prepareLight(s.light, test::observer(), 32);
    const auto normal =
            shading::renderRealtime(ps, pl, s.view, test::observer(), shading::RenderSettings{});
    s.view.eye = s.view.panel.centre - s.view.panel.normal * 0.3; // behind
    const auto behind =
            shading::renderRealtime(ps, pl, s.view, test::observer(), shading::RenderSettings{});
    expectAllFinite(behind);
    EXPECT_EQ(behind.eyeBehindPixels, static_cast<long>(behind.xyz.size()));
    s.view.eye = s.view.panel.centre + s.view.panel.up * 0.5; // exactly in the plane
    const auto inPlane =
            shading::renderRealtime(ps, pl, s.view, test::observer(), shading::RenderSettings{});
    expectAllFinite(inPlane);
    EXPECT_GT(inPlane.eyeBehindPixels, 0);
    // Diffuse is unchanged: the frame without specular is at most the normal one.
    for (std::size_t k = 0; k < normal.xyz.size(); ++k) {
        EXPECT_LE(behind.xyz[k].y, normal.xyz[k].y + 1e-9);
    }
    s.view.eye = s.view.panel.centre + s.view.panel.up * 0.5 +
                 s.view.panel.normal * 0.004; // 0.5 deg above
    const auto grazing =
            shading::renderRealtime(ps, pl, s.view, test::observer(), shading::RenderSettings{});
    expectAllFinite(grazing);
}

TEST(RenderHardCases, ExtremeRoughnessZeroLightAndHotTexelStayFinite)
{
    for (double alpha : {0.0, 1e-6, 1.0, 5.0}) {
        Case s = setup(true, true, 40.0, 12, 8);
        s.scene.alpha = alpha;
        const auto ps = shading::prepareScene(s.scene, 8);
        const auto pl = shading::prepareLight(s.light, test::observer(), 32);
        for (auto model :
             {brdf::WardModel::WardDur, brdf::WardModel::WardDurGuarded, brdf::WardModel::Gmd}) {
            s.scene.model = model;
            expectAllFinite(shading::renderRealtime(ps, pl, s.view, test::observer(),
                                                    shading::RenderSettings{}));
        }
        expectAllFinite(reference::renderReference(s.scene, s.light, s.view, test::observer()));
    }
    Case s = setup(true, true, 40.0, 12, 8);
    s.light.luminance = booth::LuminanceImage::filled(64, 32, 0.0);
    const auto ps = shading::prepareScene(s.scene, 8);
    auto pl = shading::prepareLight(s.light, test::observer(), 32);
    const auto dark =
            shading::renderRealtime(ps, pl, s.view, test::observer(), shading::RenderSettings{});
    for (const auto& v : dark.xyz) {
        ASSERT_EQ(v, colour::Xyz(0.0));
    }
    EXPECT_EQ(dark.flareClamped, 0);
    s.light.luminance.at(30, 10) = 1.0e9; // one blinding texel, far above half-float range
    pl = shading::prepareLight(s.light, test::observer(), 32);
    expectAllFinite(
            shading::renderRealtime(ps, pl, s.view, test::observer(), shading::RenderSettings{}));
}

TEST(Flare, DarkPatchUnderBrightLightClampsAtBlackAndCounts)
{
    Case s = setup(false, false, 40.0, 8, 6);
    s.scene.palette[0] = colour::Spectrum::constant(0.0005); // darker than the screen's own 0.002
    s.scene.palette[1] = colour::Spectrum::constant(0.0005);
    const auto ps = shading::prepareScene(s.scene, 8);
    const auto pl = shading::prepareLight(s.light, test::observer(), 32);
    const auto f =
            shading::renderRealtime(ps, pl, s.view, test::observer(), shading::RenderSettings{});
    EXPECT_EQ(f.flareClamped, static_cast<long>(3 * f.xyz.size()));
    for (const auto& v : f.xyz) {
        ASSERT_EQ(v, colour::Xyz(0.0));
    }
}

TEST(CompareFrames, SharmaPairsGiveThePublishedMeanAndMax)
{
    // Sharma, Wu & Dalal (2005) Table 1 pairs 1, 7, 17 and 25 (blue, zero chroma, large
    // difference, typical), laid out as two 4x1 frames through Lab -> XYZ against the reference
    // frame's white: the statistics must be those of the published differences.
    struct Pair {
        colour::Lab a, b;
        double de;
    };
    const Pair pairs[] = {{{50.0, 2.6772, -79.7751}, {50.0, 0.0, -82.7485}, 2.0425},
                          {{50.0, 0.0, 0.0}, {50.0, -1.0, 2.0}, 2.3669},
                          {{50.0, 2.5, 0.0}, {73.0, 25.0, -18.0}, 27.1492},
                          {{60.2574, -34.0099, 36.2677}, {60.4626, -34.1751, 39.4387}, 1.2644}};
    shading::XyzFrame ref, test;
    ref.width = test.width = 4;
    ref.height = test.height = 1;
    ref.whiteXyz = colour::Xyz(95.047, 100.0, 108.883);
    test.whiteXyz = colour::Xyz(1.0); // ignored: Lab is taken against the reference's white
    double sum = 0.0;
    for (const Pair& p : pairs) {
        ref.xyz.push_back(colour::labToXyz(p.a, ref.whiteXyz));
        test.xyz.push_back(colour::labToXyz(p.b, ref.whiteXyz));
        sum += p.de;
    }
    const reference::FrameError e = reference::compareFrames(ref, test);
    EXPECT_NEAR(e.mean, sum / 4.0, 1e-4);
    EXPECT_NEAR(e.max, 27.1492, 1e-4);
    EXPECT_NEAR(e.p95, 27.1492, 1e-4); // the ceil(0.95 * 4) = 4th of 4 sorted
}

} // namespace
} // namespace replica::pipeline
