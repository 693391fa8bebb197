// The booth's walls in the exact reference against closed forms: a closed box of uniform
// emission is an integrating sphere (E = E_direct / (1 - rho)), a point under a huge uniform plane
// gets pi L, walls of reflectance 0 leave the old reference bit for bit, and the shipped booth's
// solve has converged in its patch size.
#include <cmath>
#include <numbers>

#include <glm/geometric.hpp>

#include <pipeline/base/data_dir.h>
#include <pipeline/booth/booth_model.h>
#include <pipeline/booth/booth_walls.h>
#include <pipeline/reference/reference_integrator.h>
#include <pipeline/reference/wall_radiosity.h>
#include <pipeline/scene/booth.h>
#include <pipeline/surface/surface_scene.h>

#include <gtest/gtest.h>

#include "render_fixtures.h"

namespace replica::pipeline {
namespace {

using reference::Vec3;

// All six faces of the box [a, b], cut into n x n patches each, normals inward.
std::vector<booth::WallPatch> closedBox(const Vec3& a, const Vec3& b, int n)
{
    const Vec3 dx(b.x - a.x, 0, 0), dy(0, b.y - a.y, 0), dz(0, 0, b.z - a.z);
    const struct {
        Vec3 o, u, v;
    } faces[] = {{a, dz, dx},      {a, dx, dy},      {a, dy, dz},
                 {a + dx, dz, dy}, {a + dy, dx, dz}, {a + dz, dy, dx}};
    std::vector<booth::WallPatch> out;
    for (const auto& f : faces) {
        for (int j = 0; j < n; ++j) {
            for (int i = 0; i < n; ++i) {
                booth::WallPatch p;
                p.u = f.u / double(n);
                p.v = f.v / double(n);
                p.origin = f.o + double(i) * p.u + double(j) * p.v;
                p.normal = glm::normalize(glm::cross(p.u, p.v));
                p.areaM2 = glm::length(glm::cross(p.u, p.v));
                out.push_back(p);
            }
        }
    }
    return out;
}

TEST(WallReference, ClosedUniformBoxIsAnIntegratingSphere)
{
    const double e0 = 100.0;
    for (const double rho : {0.2, 0.5, 0.9}) {
        auto patches = closedBox(Vec3(-0.5, 0, -0.3), Vec3(0.5, 0.6, 0.2), 4);
        // Every face's direct irradiance the same: every patch's total is E0 / (1 - rho).
        const std::vector<double> e(patches.size(), e0);
        colour::Spectrum r = colour::Spectrum::constant(rho);
        r[0] = 0.5 * rho; // a second band value, solved on its own
        const auto w = reference::solveRadiosity(patches, e, r, colour::Spectrum::constant(1.0),
                                                 test::observer());
        EXPECT_LE(w.residual, 1e-12);
        for (std::size_t k = 0; k < w.patches.size(); ++k) {
            EXPECT_NEAR(w.radiance[k][5], rho / M_PI * e0 / (1.0 - rho), 1e-8 * e0) << k;
            EXPECT_NEAR(w.radiance[k][0], 0.5 * rho / M_PI * e0 / (1.0 - 0.5 * rho), 1e-8 * e0);
        }
        // A point anywhere inside, facing anywhere, sees the whole box: E = pi L.
        const Vec3 n = glm::normalize(Vec3(0.3, 0.8, -0.5));
        const auto s = reference::integrateWalls(w, Vec3(0.1, 0.2, -0.05), n, n, n,
                                                 brdf::WardModel::WardDur, 0.1, false, nullptr,
                                                 Vec3(1, 0, 0), Vec3(0, 1, 0));
        EXPECT_NEAR(s.irradiance[5], e0 * rho / (1.0 - rho), 1e-8 * e0) << rho;
        EXPECT_NEAR(s.geoIrradianceY, M_PI * w.luminance[0], 1e-8 * e0);
    }
}

TEST(WallReference, PointUnderAHugeUniformPlaneGetsPiL)
{
    booth::WallLight w;
    booth::WallPatch p;
    p.origin = Vec3(-500, 0, -500);
    p.u = Vec3(0, 0, 1000); // z x x = +y: facing up
    p.v = Vec3(1000, 0, 0);
    p.normal = Vec3(0, 1, 0);
    w.patches = {p};
    w.radiance = {colour::Spectrum::constant(80.0)};
    w.luminance = {80.0};
    const Vec3 down(0, -1, 0);
    const auto s = reference::integrateWalls(w, Vec3(0, 0.3, 0), down, down, down,
                                             brdf::WardModel::WardDur, 0.1, false, nullptr,
                                             Vec3(1, 0, 0), Vec3(0, 0, 1));
    EXPECT_NEAR(s.geoIrradianceY, M_PI * 80.0, 1e-3 * M_PI * 80.0);
    // A facet tilted t from facing the plane sees part of it: its view factor to an infinite
    // plane is (1 + cos t) / 2.
    const double t = 60.0 * M_PI / 180.0;
    const Vec3 n(std::sin(t), -std::cos(t), 0);
    const auto tilted =
            reference::integrateWalls(w, Vec3(0, 0.3, 0), n, n, n, brdf::WardModel::WardDur, 0.1,
                                      false, nullptr, Vec3(0, 0, 1), Vec3(1, 0, 0));
    EXPECT_NEAR(tilted.geoIrradianceY, M_PI * 80.0 * (1 + std::cos(t)) / 2, 1e-3 * M_PI * 80.0);
}

struct Shipped {
    booth::Booth booth;
    surface::SurfaceScene checker, painting;
};

const Shipped& shipped()
{
    static const Shipped s = [] {
        auto booth = booth::loadBooth(dataDir() / "booth");
        auto checker = surface::loadScene(dataDir() / "scenes" / "colorchecker");
        auto painting = surface::loadScene(dataDir() / "scenes" / "painting");
        EXPECT_TRUE(booth && checker && painting);
        return Shipped{*booth, *checker, *painting};
    }();
    return s;
}

TEST(WallReference, WallsOfReflectanceZeroGiveTheOldReferenceBitForBit)
{
    const auto& s = shipped();
    const booth::BoothLight& light = s.booth.lights.front();
    booth::BoothWalls black = scene::defaultBoothWalls(light);
    black.reflectance = colour::Spectrum{};
    reference::WallSolveOptions coarse;
    coarse.patchM = 0.1;
    const booth::WallLight w = reference::solveWalls(black, light, test::observer(), coarse);
    ASSERT_FALSE(w.empty());
    for (const auto* scene : {&s.checker, &s.painting}) {
        shading::View view;
        view.panel = scene::panelPose(scene::degreesToRadians(30.0));
        view.pixelsX = 12;
        view.pixelsY = 8;
        reference::ReferenceOptions without;
        without.horizonAzimuths = 36;
        reference::ReferenceOptions with = without;
        with.walls = &w;
        const auto a = reference::renderReference(*scene, light, view, test::observer(), without);
        const auto b = reference::renderReference(*scene, light, view, test::observer(), with);
        ASSERT_EQ(a.xyz.size(), b.xyz.size());
        for (std::size_t k = 0; k < a.xyz.size(); ++k) {
            EXPECT_EQ(a.xyz[k].x, b.xyz[k].x) << scene->name << " " << k;
            EXPECT_EQ(a.xyz[k].y, b.xyz[k].y);
            EXPECT_EQ(a.xyz[k].z, b.xyz[k].z);
        }
        EXPECT_EQ(a.whiteY, b.whiteY);
    }
}

TEST(WallReference, ShippedBoothConvergesInPatchSize)
{
    const auto& s = shipped();
    const booth::BoothLight& light = s.booth.lights.front();
    const booth::BoothWalls walls = scene::defaultBoothWalls(light);
    EXPECT_NEAR(walls.boxMax.y, 0.62, 1e-12);
    EXPECT_NEAR(walls.boxMax.x - walls.boxMin.x, 1.0, 1e-12);
    const scene::PanelPose panel = scene::panelPose(scene::degreesToRadians(30.0));
    double previous = 0.0;
    for (const double patch : {0.1, 0.05, 0.025}) {
        reference::WallSolveOptions o;
        o.patchM = patch;
        const auto w = reference::solveWalls(walls, light, test::observer(), o);
        EXPECT_LE(w.residual, 1e-12);
        const Vec3 n = panel.normal;
        double e = 0.0;
        for (const double du : {-0.4, 0.0, 0.4}) {
            const Vec3 p = panel.centre + du * panel.rightEdgeM();
            e += reference::integrateWalls(w, p, n, n, n, brdf::WardModel::WardDur, 0.1, false,
                                           nullptr, panel.right, panel.up)
                         .geoIrradianceY;
        }
        if (patch < 0.1) {
            // Halving the patches moves the walls' light on the panel by under 1 % (0.05 m,
            // the reference's default) and 0.5 % (0.025 m).
            EXPECT_NEAR(e, previous, (patch < 0.05 ? 0.005 : 0.01) * previous) << patch;
        }
        previous = e;
    }
    // Grey walls under a ceiling that lights the panel with about a thousand lux add a few
    // percent to it, never nothing and never as much as the ceiling.
    const auto direct = reference::integrateTexels(
            reference::texelCloud(light), panel.centre, panel.normal, panel.normal, panel.normal,
            brdf::WardModel::WardDur, 0.1, false, nullptr, panel.right, panel.up);
    EXPECT_GT(previous / 3.0, 0.001 * direct.geoIrradiance);
    EXPECT_LT(previous / 3.0, 0.3 * direct.geoIrradiance);
}

} // namespace
} // namespace replica::pipeline
