// The area-light diffuse term (shading::RenderSettings::areaLights) against closed forms it does
// not use: a fine 2-D quadrature of L cos(theta_s) cos(theta_l) / d^2 over the emitter, and the
// classic form factor of a rectangle parallel to the surface. A flat matte surface under a
// uniform rectangular lamp at several orientations, partly behind the surface's plane (clipped)
// and not; then whole frames of the CPU model at every tilt from -30 to 85 degrees, and the hard
// cases (tilts to 89 degrees, 1 and 1e5 cd/m^2, a one-texel-wide lamp).
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <numbers>

#include <glm/geometric.hpp>

#include <pipeline/reference/reference_integrator.h>
#include <pipeline/shading/realtime_model.h>

#include <gtest/gtest.h>

#include "render_fixtures.h"

namespace replica::pipeline::shading {
namespace {

// E at p (normal n) from the uniform rectangle origin + s eu + t ev (s, t in [0, 1], emitting
// along normalize(cross(eu, ev))) of luminance L: Gauss-Legendre (4 points) on an n x n grid of
// cells, both cosines clamped at 0. The clamp is a kink along the horizon; cells are small enough
// that it costs < 1e-6 relative at the distances used here.
double quadrature(const Vec3& origin,
                  const Vec3& eu,
                  const Vec3& ev,
                  double lum,
                  const Vec3& p,
                  const Vec3& n,
                  int cells = 400)
{
    static constexpr std::array<double, 4> x{-0.8611363115940526, -0.3399810435848563,
                                             0.3399810435848563, 0.8611363115940526};
    static constexpr std::array<double, 4> w{0.3478548451374538, 0.6521451548625461,
                                             0.6521451548625461, 0.3478548451374538};
    const Vec3 nl = glm::normalize(glm::cross(eu, ev));
    const double area = glm::length(glm::cross(eu, ev));
    const double h = 1.0 / cells;
    double sum = 0.0;
    for (int i = 0; i < cells; ++i) {
        for (int j = 0; j < cells; ++j) {
            for (int a = 0; a < 4; ++a) {
                for (int b = 0; b < 4; ++b) {
                    const double s = (i + 0.5 + 0.5 * x[a]) * h;
                    const double t = (j + 0.5 + 0.5 * x[b]) * h;
                    const Vec3 d = origin + s * eu + t * ev - p;
                    const double d2 = glm::dot(d, d);
                    const double len = std::sqrt(d2);
                    const double cs = std::max(glm::dot(n, d) / len, 0.0);
                    const double cl = std::max(-glm::dot(nl, d) / len, 0.0);
                    sum += w[a] * w[b] * cs * cl / d2;
                }
            }
        }
    }
    return lum * sum * 0.25 * h * h * area;
}

// The form factor from a point to a parallel rectangle a x b with one corner straight above it at
// height c (Howell's catalogue, C-11): E = pi L F.
double cornerFormFactor(double a, double b, double c)
{
    const double x = a / c;
    const double y = b / c;
    const double sx = std::sqrt(1.0 + x * x);
    const double sy = std::sqrt(1.0 + y * y);
    return (x / sx * std::atan(y / sx) + y / sy * std::atan(x / sy)) / (2.0 * std::numbers::pi);
}

booth::PointLight uniformRegion(const Vec3& origin, const Vec3& eu, const Vec3& ev, double lum)
{
    booth::PointLight r;
    r.regionOrigin = origin;
    r.regionU = eu;
    r.regionV = ev;
    r.meanCdM2 = lum;
    r.position = origin + 0.5 * (eu + ev);
    r.sumCdM2 = lum; // one texel: only its sign matters here
    return r;
}

TEST(AreaLight, ParallelRectangleMatchesTheCornerFormFactor)
{
    // A 0.8 x 0.6 m lamp 0.5 m above, facing down; points under it and beside it.
    const Vec3 origin(-0.4, 0.5, -0.3);
    const Vec3 eu(0.8, 0.0, 0.0);
    const Vec3 ev(0.0, 0.0, 0.6); // cross(eu, ev) = -y: emits downwards
    const auto region = uniformRegion(origin, eu, ev, 1000.0);
    const Vec3 n(0.0, 1.0, 0.0);
    const Vec3 nl = glm::normalize(glm::cross(eu, ev));
    for (const Vec3& p :
         {Vec3(0.0, 0.0, 0.0), Vec3(0.3, 0.1, 0.2), Vec3(-0.4, 0.0, -0.3), Vec3(0.7, 0.2, 0.5)}) {
        // Four rectangles with a corner above p, signed (p may be outside the lamp's shadow).
        const double c = 0.5 - p.y;
        const double x0 = origin.x - p.x, x1 = origin.x + eu.x - p.x;
        const double z0 = origin.z - p.z, z1 = origin.z + ev.z - p.z;
        const auto f = [c](double x, double z) {
            return std::copysign(1.0, x) * std::copysign(1.0, z) *
                   cornerFormFactor(std::abs(x), std::abs(z), c);
        };
        const double exact =
                std::numbers::pi * 1000.0 * (f(x1, z1) - f(x0, z1) - f(x1, z0) + f(x0, z0));
        const double e = regionIrradiance(region, nl, p, n, n);
        EXPECT_NEAR(e, exact, 1e-9 * exact) << p.x << ", " << p.z;
        EXPECT_NEAR(quadrature(origin, eu, ev, 1000.0, p, n), exact, 1e-6 * exact);
    }
}

TEST(AreaLight, EveryOrientationClippedOrNotMatchesTheQuadrature)
{
    // The lamp 0.5 m above the origin, the surface's normal turned from facing it (parallel)
    // through tilted to perpendicular and past: from about 60 degrees part of the lamp is below
    // the surface's horizon and the polygon is clipped.
    const Vec3 origin(-0.5, 0.5, -0.25);
    const Vec3 eu(1.0, 0.0, 0.0);
    const Vec3 ev(0.0, 0.0, 0.5);
    const auto region = uniformRegion(origin, eu, ev, 1000.0);
    const Vec3 nl = glm::normalize(glm::cross(eu, ev));
    int clipped = 0;
    for (const double turnDeg : {0.0, 30.0, 60.0, 80.0, 90.0, 110.0, 150.0}) {
        const double r = turnDeg * std::numbers::pi / 180.0;
        for (const Vec3& axisTurn :
             {Vec3(std::sin(r), std::cos(r), 0.0), Vec3(0.0, std::cos(r), std::sin(r)),
              glm::normalize(Vec3(std::sin(r), std::cos(r), std::sin(r)))}) {
            for (const Vec3& p : {Vec3(0.0, 0.0, 0.0), Vec3(0.45, 0.2, 0.2), Vec3(-0.2, 0.45, 0.0),
                                  Vec3(0.9, 0.1, -0.4)}) {
                const Vec3 n = glm::normalize(axisTurn);
                const double want = quadrature(origin, eu, ev, 1000.0, p, n);
                const double e = regionIrradiance(region, nl, p, n, n);
                // Relative where there is light (the quadrature's own error near the lamp and
                // across the horizon's kink is about 1e-5), absolute against pi L where not.
                EXPECT_NEAR(e, want, 3e-5 * want + 1e-9 * std::numbers::pi * 1000.0)
                        << turnDeg << " deg, p " << p.x << " " << p.y << " " << p.z;
                // Corners on both sides of the horizon: the clipped case.
                int above = 0;
                for (const Vec3& q : {origin, origin + eu, origin + ev, origin + eu + ev}) {
                    above += glm::dot(n, q - p) > 0.0 ? 1 : 0;
                }
                clipped += above > 0 && above < 4 ? 1 : 0;
            }
        }
    }
    EXPECT_GT(clipped, 10); // the clip was exercised, not only the whole polygon
}

TEST(AreaLight, TheFacetsHorizonClipsWithinTheMacroSurfacesHorizon)
{
    // Relief: a facet tilted away from the macro normal sees the part of the lamp above both
    // horizons; the quadrature of cos_s with both cosines' planes as a mask.
    const Vec3 origin(-0.5, 0.5, -0.25);
    const Vec3 eu(1.0, 0.0, 0.0);
    const Vec3 ev(0.0, 0.0, 0.5);
    const auto region = uniformRegion(origin, eu, ev, 1000.0);
    const Vec3 nl = glm::normalize(glm::cross(eu, ev));
    const Vec3 nGeo = glm::normalize(Vec3(1.0, 0.3, 0.0)); // the lamp mostly behind the panel
    const Vec3 nShade = glm::normalize(Vec3(1.0, 0.6, 0.2));
    const Vec3 p(0.1, 0.2, 0.0);
    // Both masks: the quadrature with cos_s, and points below the macro horizon dropped.
    const int cells = 800;
    double sum = 0.0;
    for (int i = 0; i < cells; ++i) {
        for (int j = 0; j < cells; ++j) {
            const Vec3 d = origin + ((i + 0.5) / cells) * eu + ((j + 0.5) / cells) * ev - p;
            const double d2 = glm::dot(d, d);
            const double len = std::sqrt(d2);
            if (glm::dot(nGeo, d) <= 0.0) {
                continue;
            }
            sum += std::max(glm::dot(nShade, d) / len, 0.0) * (-glm::dot(nl, d) / len) / d2;
        }
    }
    const double want = 1000.0 * sum * 0.5 / (cells * cells);
    const double e = regionIrradiance(region, nl, p, nGeo, nShade);
    EXPECT_NEAR(e, want, 2e-4 * want);                             // midpoint rule across two kinks
    EXPECT_LT(e, regionIrradiance(region, nl, p, nShade, nShade)); // the macro horizon cut some
}

TEST(AreaLight, SingularPointsStayFiniteAndBounded)
{
    const Vec3 origin(-0.5, 0.5, -0.25);
    const Vec3 eu(1.0, 0.0, 0.0);
    const Vec3 ev(0.0, 0.0, 0.5);
    const auto region = uniformRegion(origin, eu, ev, 1000.0);
    const Vec3 nl = glm::normalize(glm::cross(eu, ev));
    const Vec3 up(0.0, 1.0, 0.0);
    // In the lamp's plane (on it, on an edge, at a corner, beside it) and behind it: nothing.
    for (const Vec3& p : {Vec3(0.0, 0.5, 0.0), Vec3(0.5, 0.5, 0.0), origin, Vec3(0.9, 0.5, 0.0),
                          Vec3(0.0, 0.6, 0.0)}) {
        EXPECT_EQ(regionIrradiance(region, nl, p, up, up), 0.0);
    }
    // Just under the middle: a hemisphere of lamp, E -> pi L; under an edge, half that.
    for (const double gap : {1e-3, 1e-6, 1e-9}) {
        const double mid = regionIrradiance(region, nl, Vec3(0.0, 0.5 - gap, 0.0), up, up);
        EXPECT_NEAR(mid, std::numbers::pi * 1000.0, 2e-2 * std::numbers::pi * 1000.0) << gap;
        const double edge = regionIrradiance(region, nl, Vec3(0.5, 0.5 - gap, 0.0), up, up);
        EXPECT_NEAR(edge, 0.5 * std::numbers::pi * 1000.0, 2e-2 * std::numbers::pi * 1000.0);
    }
    // A zero-size region, and edges of zero length after clipping (a corner on the horizon).
    const auto dot = uniformRegion(origin, Vec3(0.0), Vec3(0.0), 1000.0);
    EXPECT_EQ(regionIrradiance(dot, nl, Vec3(0.0), up, up), 0.0);
    const Vec3 p(-0.5, 0.0, -0.25);
    const Vec3 n = glm::normalize(glm::cross(Vec3(0.0, 0.5, 0.0), Vec3(1.0, 0.0, 0.5)));
    const double e = regionIrradiance(region, nl, p, n, n);
    EXPECT_TRUE(std::isfinite(e));
    EXPECT_NEAR(e, quadrature(origin, eu, ev, 1000.0, p, n), 1e-5 * std::numbers::pi * 1000.0);
}

// A flat matte surface under a uniform 1.0 x 0.5 m lamp 0.6 m up (the shipped ceiling's size),
// rendered by the CPU model: each pixel's Y against the quadrature's. Spectral36 channels make
// the colour exact (Y = (rho_Y - flare rho) E / pi, the unit-luminance light's Y being 1), so
// what remains is eq. (1).
struct MatteCase {
    surface::SurfaceScene scene = test::testScene(40, 24, false, false);
    booth::BoothLight light;
    double rhoY[2] = {0.0, 0.0}; // the two pigments' Y under the unit-luminance light
};

double worstFrameError(const MatteCase& c,
                       const PreparedLight& pl,
                       double tiltDeg,
                       bool area,
                       const Vec3& eye = Vec3(0.0, 0.45, 0.60))
{
    RenderSettings s;
    s.areaLights = area;
    s.channels = ChannelRep::Spectral36;
    s.diffuseGrid = 0;
    View view;
    view.panel = scene::panelPose(scene::degreesToRadians(tiltDeg));
    view.eye = eye;
    view.pixelsX = 10;
    view.pixelsY = 6;
    const PreparedScene ps = prepareScene(c.scene, 8);
    const XyzFrame f = renderRealtime(ps, pl, view, test::observer(), s);
    EXPECT_EQ(f.nonFinite, 0);
    const booth::BoothLight& l = c.light;
    const Vec3 origin = l.centre - 0.5 * (l.edgeU + l.edgeV);
    const double lum = l.luminance.at(0, 0);
    double worst = 0.0;
    for (int py = 0; py < view.pixelsY; ++py) {
        for (int px = 0; px < view.pixelsX; ++px) {
            const ShadingPoint sp = shadingPoint(view, c.scene, {}, px, py);
            const double e = quadrature(origin, l.edgeU, l.edgeV, lum, sp.p, sp.nGeo, 160);
            const int pigment = sp.tx < c.scene.width / 2 ? 0 : 1;
            const double want = (c.rhoY[pigment] - kScreenFlareRho) * e / std::numbers::pi;
            const double got = f.xyz[static_cast<std::size_t>(py) * view.pixelsX + px].y;
            if (want > 1e-3) {
                worst = std::max(worst, std::abs(got / want - 1.0));
            }
        }
    }
    return worst;
}

MatteCase matteCase(double lum, int texelsU = 64, int texelsV = 32)
{
    MatteCase c;
    c.light = test::ceilingLight(texelsU, texelsV, lum, 0.6, 1.0, 0.5);
    const colour::Spectrum unit = booth::unitLuminanceSpd(test::observer(), c.light.spd);
    for (int k = 0; k < 2; ++k) {
        c.rhoY[k] = colour::spectrumToXyz(test::observer(), c.scene.palette[k] * unit).y;
    }
    return c;
}

TEST(AreaLight, MatteFramesAreWithinATenthOfAPercentAtEveryTilt)
{
    const MatteCase c = matteCase(1000.0);
    const PreparedLight pl = prepareLight(c.light, test::observer(), 32);
    // The goal is 0.5 % at every tilt from -30 to 85 degrees; uniform regions summed exactly are
    // the lamp, so the model should be exact to the quadrature's accuracy.
    double worstArea = 0.0, worstPoint = 0.0;
    for (const double tilt :
         {-30.0, -20.0, -10.0, 0.0, 8.0, 10.0, 20.0, 30.0, 45.0, 60.0, 75.0, 85.0}) {
        const double area = worstFrameError(c, pl, tilt, true);
        const double point = worstFrameError(c, pl, tilt, false);
        EXPECT_LT(area, 1e-4) << tilt << " deg";
        worstArea = std::max(worstArea, area);
        worstPoint = std::max(worstPoint, point);
        std::printf("[ matte ] tilt %5.1f: max |dY/Y| area %.2e, 32 point lights %.2e\n", tilt,
                    area, point);
    }
    // The point lights' near-field error that area lights remove (the issue measured 2-12 %).
    EXPECT_GT(worstPoint, 0.005);
    RecordProperty("worst_area", std::to_string(worstArea));
    RecordProperty("worst_point", std::to_string(worstPoint));
}

TEST(AreaLight, HardCasesMatchTheQuadrature)
{
    // Tilts of 80 to 89 degrees (the panel nearly facing the lamp edge-on), grazing eyes (the
    // eye moves nothing of a matte surface's diffuse term, but the frame must not change by it),
    // booths at 1 and 1e5 cd/m^2.
    for (const double lum : {1.0, 1e5}) {
        const MatteCase c = matteCase(lum);
        const PreparedLight pl = prepareLight(c.light, test::observer(), 32);
        for (const double tilt : {80.0, 85.0, 87.0, 89.0}) {
            EXPECT_LT(worstFrameError(c, pl, tilt, true), 1e-4) << lum << " cd/m^2, " << tilt;
        }
        for (const Vec3& eye : {Vec3(0.0, 0.35, 0.01), Vec3(0.6, 0.3, 0.02)}) {
            EXPECT_LT(worstFrameError(c, pl, 30.0, true, eye), 1e-4) << lum << " cd/m^2";
        }
    }
}

TEST(AreaLight, OneTexelWideLampIsTheStripItIs)
{
    // One lit column of a 64 x 32 ceiling: the regions' rectangles shrink to the lit texels, so
    // the strip is not spread over the dark around it. Checked against the strip's quadrature.
    MatteCase c = matteCase(0.0);
    for (int y = 0; y < c.light.luminance.height; ++y) {
        c.light.luminance.at(40, y) = 5000.0;
    }
    const PreparedLight pl = prepareLight(c.light, test::observer(), 32);
    RenderSettings s;
    s.channels = ChannelRep::Spectral36;
    View view;
    view.pixelsX = 8;
    view.pixelsY = 5;
    const PreparedScene ps = prepareScene(c.scene, 8);
    const Vec3 stripOrigin = c.light.pointAtTexel(40, 0);
    const Vec3 eu = c.light.pointAtTexel(41, 0) - stripOrigin;
    for (const double tilt : {-20.0, 10.0, 45.0, 85.0}) {
        view.panel = scene::panelPose(scene::degreesToRadians(tilt));
        const XyzFrame f = renderRealtime(ps, pl, view, test::observer(), s);
        for (int py = 0; py < view.pixelsY; ++py) {
            for (int px = 0; px < view.pixelsX; ++px) {
                const ShadingPoint sp = shadingPoint(view, c.scene, {}, px, py);
                const double e =
                        quadrature(stripOrigin, eu, c.light.edgeV, 5000.0, sp.p, sp.nGeo, 200);
                const int pigment = sp.tx < c.scene.width / 2 ? 0 : 1;
                const double want = (c.rhoY[pigment] - kScreenFlareRho) * e / std::numbers::pi;
                const double got = f.xyz[static_cast<std::size_t>(py) * view.pixelsX + px].y;
                EXPECT_NEAR(got, want, 1e-4 * want + 1e-9) << tilt << " deg, " << px << "," << py;
            }
        }
    }
}

TEST(AreaLight, TheExactReferenceAgreesWithTheQuadrature)
{
    // The reference integrates the lamp's texels as small squares; on a uniform lamp it must
    // agree with the quadrature as the model does.
    const MatteCase c = matteCase(1000.0);
    View view;
    view.pixelsX = 6;
    view.pixelsY = 4;
    const Vec3 origin = c.light.centre - 0.5 * (c.light.edgeU + c.light.edgeV);
    for (const double tilt : {-20.0, 10.0, 60.0}) {
        view.panel = scene::panelPose(scene::degreesToRadians(tilt));
        const XyzFrame ref = reference::renderReference(c.scene, c.light, view, test::observer());
        double worst = 0.0;
        for (int py = 0; py < view.pixelsY; ++py) {
            for (int px = 0; px < view.pixelsX; ++px) {
                const ShadingPoint sp = shadingPoint(view, c.scene, {}, px, py);
                const double e = quadrature(origin, c.light.edgeU, c.light.edgeV, 1000.0, sp.p,
                                            sp.nGeo, 160);
                const int pigment = sp.tx < c.scene.width / 2 ? 0 : 1;
                const double want = (c.rhoY[pigment] - kScreenFlareRho) * e / std::numbers::pi;
                worst = std::max(
                        worst,
                        std::abs(ref.xyz[static_cast<std::size_t>(py) * view.pixelsX + px].y /
                                         want -
                                 1.0));
            }
        }
        // The reference sums the 64 x 32 texels, each about 1.6 cm, some 10 cm from the
        // surface's top edge at -20 degrees: 0.12 % there, less elsewhere.
        EXPECT_LT(worst, 2e-3) << tilt << " deg";
        std::printf("[ reference ] tilt %5.1f: max |dY/Y| %.2e\n", tilt, worst);
    }
}

} // namespace
} // namespace replica::pipeline::shading
