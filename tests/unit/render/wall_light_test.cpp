// The real-time renderer's walls (shading/wall_field.h, glsl/booth_walls.glsl): the CPU model's
// field against the walls' exact light, the CPU model's frame off the walls bit for bit the old
// one, and the GL pass with walls against the CPU model it follows.
#include <algorithm>
#include <cmath>
#include <utility>

#include <glm/geometric.hpp>

#include <pipeline/booth/booth_walls.h>
#include <pipeline/reference/wall_radiosity.h>
#include <pipeline/render/booth_shading_pass.h>
#include <pipeline/scene/booth.h>
#include <pipeline/shading/realtime_model.h>
#include <pipeline/shading/wall_field.h>

#include <gtest/gtest.h>

#include "../support/headless_gl.h"
#include "render_fixtures.h"

namespace replica::pipeline {
namespace {

using shading::Vec3;

// The test lamp (1.0 x 0.5 m at 0.6 m) in its N7 box, solved coarsely.
struct Lit {
    booth::BoothLight light = test::stripedLight(64, 32);
    booth::WallLight walls;
    Lit()
    {
        reference::WallSolveOptions o;
        o.patchM = 0.1;
        walls = reference::solveWalls(scene::defaultBoothWalls(light), light, test::observer(), o);
    }
};

const Lit& lit()
{
    static const Lit l;
    return l;
}

TEST(WallField, NodesAreTheWallsExactLightAndTheFieldInterpolatesThem)
{
    const surface::SurfaceScene scene = test::testScene(40, 24, false, false);
    for (const double tilt : {0.0, 30.0, 60.0}) {
        const auto panel = scene::panelPose(scene::degreesToRadians(tilt));
        const shading::WallField f = shading::wallField(lit().walls, panel, scene);
        shading::View view;
        view.panel = panel;
        const std::vector<Vec3> flat;
        for (const double u : {0.0, 0.25, 0.5, 0.8, 1.0}) {
            for (const double v : {0.0, 0.5, 0.7, 1.0}) {
                const auto sp = shading::shadingPointAt(view, scene, flat, u, v);
                const double exact = shading::wallIrradiance(lit().walls, sp.p, sp.nGeo, nullptr);
                const double field = shading::wallFieldAt(f, u, v, sp.nGeo, sp.nGeo);
                // At the nodes exactly; between them within 2 % of the walls' light.
                const bool node =
                        (u == 0.0 || u == 0.5 || u == 1.0) && (v == 0.0 || v == 0.5 || v == 1.0);
                EXPECT_NEAR(field, exact, node ? 1e-9 * exact : 0.02 * exact) << tilt << " " << u;
                EXPECT_GT(exact, 0.0);
            }
        }
        // A facet tipped towards a side wall. The vector irradiance is the exact first
        // derivative (the clamped cosine is 0 on the horizon), but at the centre the side walls
        // are symmetric, the first-order change is near zero and the true change second order;
        // measured: within 1.5 % of the walls' light at 3 degrees and 6 % at 10 (about 4.7 %),
        // where ignoring the facet is nearer (3.3 %): the facet term is left to improve
        // (docs/rendering.md, "The booth's walls"). Both are a few tenths of a percent of the
        // frame's light.
        const auto sp = shading::shadingPointAt(view, scene, flat, 0.5, 0.5);
        for (const auto& [deg, bound] : {std::pair{3.0, 0.015}, std::pair{10.0, 0.06}}) {
            const Vec3 n = glm::normalize(sp.nGeo + std::tan(deg * M_PI / 180.0) * sp.right);
            const double exact = shading::wallIrradiance(lit().walls, sp.p, n, nullptr);
            EXPECT_NEAR(shading::wallFieldAt(f, 0.5, 0.5, sp.nGeo, n), exact, bound * exact)
                    << tilt << " " << deg;
        }
    }
}

TEST(WallField, CpuModelWithoutWallsIsTheOldFrameAndWithWallsBrighter)
{
    const surface::SurfaceScene scene = test::testScene(40, 24, true, true);
    const auto ps = shading::prepareScene(scene, 8);
    auto pl = shading::prepareLight(lit().light, test::observer(), 32);
    shading::View view;
    view.panel = scene::panelPose(scene::degreesToRadians(30.0));
    view.pixelsX = 20;
    view.pixelsY = 12;
    shading::RenderSettings s;
    const auto old = shading::renderRealtime(ps, pl, view, test::observer(), s);
    pl.walls = &lit().walls;
    const auto off = shading::renderRealtime(ps, pl, view, test::observer(), s);
    s.walls = true;
    const auto on = shading::renderRealtime(ps, pl, view, test::observer(), s);
    pl.walls = nullptr;
    const auto none = shading::renderRealtime(ps, pl, view, test::observer(), s);
    for (std::size_t k = 0; k < old.xyz.size(); ++k) {
        EXPECT_EQ(old.xyz[k].y, off.xyz[k].y) << k;
        EXPECT_EQ(old.xyz[k].y, none.xyz[k].y) << k;
        EXPECT_GT(on.xyz[k].y, old.xyz[k].y) << k;
    }
    EXPECT_EQ(old.whiteY, off.whiteY);
    EXPECT_GT(on.whiteY, old.whiteY);
}

using WallLightGl = tests::HeadlessGlTest;

TEST_F(WallLightGl, GlPassWithWallsFollowsTheCpuModel)
{
    for (const bool bumpy : {false, true}) {
        const surface::SurfaceScene scene = test::testScene(40, 24, bumpy, true);
        const auto ps = shading::prepareScene(scene, 8);
        auto pl = shading::prepareLight(lit().light, test::observer(), 32);
        pl.walls = &lit().walls;
        shading::RenderSettings s;
        s.walls = true;
        auto pass = render::BoothShadingPass::create(ps, s, test::observer());
        ASSERT_TRUE(pass) << pass.error().message;
        ASSERT_TRUE((*pass)->setLight(pl));
        for (const double tilt : {10.0, 40.0}) {
            shading::View view;
            view.panel = scene::panelPose(scene::degreesToRadians(tilt));
            view.pixelsX = 20;
            view.pixelsY = 12;
            auto gl = render::renderBoothFrame(**pass, pl, view);
            ASSERT_TRUE(gl) << gl.error().message;
            const auto cpu = shading::renderRealtime(ps, pl, view, test::observer(), s);
            s.walls = false;
            const auto noWalls = shading::renderRealtime(ps, pl, view, test::observer(), s);
            s.walls = true;
            double worst = 0.0;
            double added = 0.0;
            for (std::size_t k = 0; k < cpu.xyz.size(); ++k) {
                worst = std::max(worst, std::abs(gl->xyz[k].y - cpu.xyz[k].y) / cpu.xyz[k].y);
                added = std::max(added, (cpu.xyz[k].y - noWalls.xyz[k].y) / cpu.xyz[k].y);
            }
            // The walls add a visible share and the GL pass carries it as the CPU model does.
            EXPECT_GT(added, 0.005) << bumpy << " " << tilt;
            EXPECT_LT(worst, 2e-3) << bumpy << " " << tilt;
            EXPECT_NEAR(gl->whiteY, cpu.whiteY, 1e-9 * cpu.whiteY);
        }
    }
}

} // namespace
} // namespace replica::pipeline
