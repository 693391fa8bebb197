// The specular grid of the CPU model (shading::gridNodes, gridValue): node layout,
// interpolation that is exact for bilinear functions, what the grid costs the ColorChecker
// against shading the specular term per pixel, the spacing chosen for relief from how fast it
// turns, and what that costs the glossy cylinder against the exact reference.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>

#include <pipeline/base/data_dir.h>
#include <pipeline/booth/booth_model.h>
#include <pipeline/colour/ciede2000.h>
#include <pipeline/colour/cielab.h>
#include <pipeline/reference/frame_error.h>
#include <pipeline/reference/reference_integrator.h>
#include <pipeline/scene/stand.h>
#include <pipeline/shading/realtime_model.h>
#include <pipeline/spectral/adaptive_encoding.h>

#include <gtest/gtest.h>

namespace replica::pipeline::shading {
namespace {

TEST(SpecularGrid, NodesCoverTheSurfaceCornersIncluded)
{
    surface::SurfaceScene s;
    s.width = 275;
    s.height = 185;
    const GridNodes g8 = gridNodes(s, 8);
    EXPECT_EQ(g8.x, 36); // ceil(275 / 8) + 1
    EXPECT_EQ(g8.y, 25); // ceil(185 / 8) + 1
    const GridNodes g1 = gridNodes(s, 1);
    EXPECT_EQ(g1.x, 276);
    EXPECT_EQ(g1.y, 186);
    // Coarser than the surface: still two nodes a side (the corners).
    const GridNodes big = gridNodes(s, 1000);
    EXPECT_EQ(big.x, 2);
    EXPECT_EQ(big.y, 2);
    EXPECT_EQ(gridNodes(s, 0).x, 0);
    EXPECT_EQ(gridNodes(s, -3).y, 0);
    surface::SurfaceScene empty;
    EXPECT_EQ(gridNodes(empty, 8).x, 0);
}

TEST(SpecularGrid, InterpolationIsExactForBilinearFunctionsAndHitsTheNodes)
{
    const GridNodes g{7, 4};
    const auto f = [](double u, double v) { return 0.3 + 2.0 * u - 1.5 * v + 4.0 * u * v; };
    std::vector<double> values;
    for (int j = 0; j < g.y; ++j) {
        for (int i = 0; i < g.x; ++i) {
            values.push_back(
                    f(static_cast<double>(i) / (g.x - 1), static_cast<double>(j) / (g.y - 1)));
        }
    }
    for (double u : {0.0, 0.013, 0.5, 0.77, 1.0}) {
        for (double v : {0.0, 0.25, 0.333, 0.99, 1.0}) {
            EXPECT_NEAR(gridValue(values, g, u, v), f(u, v), 1e-12) << u << ", " << v;
        }
    }
    // At a node: its own value, not a blend.
    EXPECT_DOUBLE_EQ(gridValue(values, g, 2.0 / 6.0, 1.0 / 3.0), values[1 * 7 + 2]);
    // Outside [0, 1]^2: clamped to the edge, never read out of bounds.
    EXPECT_NEAR(gridValue(values, g, -0.5, 1.5), f(0.0, 1.0), 1e-12);
}

TEST(SpecularGrid, CostsTheFlatColorCheckerLittleAgainstPerPixelShading)
{
    auto obs = colour::loadCie1931(dataDir());
    auto booth = booth::loadBooth(dataDir() / "booth");
    auto scene = surface::loadScene(dataDir() / "scenes" / "colorchecker");
    ASSERT_TRUE(obs && booth && scene);
    View view;
    view.panel = scene::panelPose(scene::degreesToRadians(30.0));
    view.pixelsX = 96;
    view.pixelsY = 64;
    RenderSettings perPixel;
    RenderSettings grid = perPixel;
    grid.specularGrid = kFlatSpecularGrid;
    const PreparedScene ps = prepareScene(*scene, perPixel.horizonDirections);
    const PreparedLight pl = prepareLight(booth->lights[2], *obs, perPixel.lights);
    const XyzFrame a = renderRealtime(ps, pl, view, *obs, perPixel);
    const XyzFrame b = renderRealtime(ps, pl, view, *obs, grid);
    const reference::FrameError e = reference::compareFrames(a, b);
    // The grid changes the specular term (it is not silently off) ...
    EXPECT_GT(e.max, 1e-4);
    // ... by much less than the budget: the sampling noise of 48 samples is of the same order.
    EXPECT_LE(e.p95, 0.5);
    EXPECT_LE(e.max, 1.0);
    RecordProperty("grid_vs_per_pixel_p95", std::to_string(e.p95));
    RecordProperty("grid_vs_per_pixel_max", std::to_string(e.max));
}

// A glossy cylinder of radius R across the rows of a 24 x 16 cm surface at 1 mm texels, as the
// shipped one is made.
surface::SurfaceScene cylinderScene(double radiusM, double alpha)
{
    surface::SurfaceScene s;
    s.width = 240;
    s.height = 160;
    s.widthM = 0.24;
    s.heightM = 0.16;
    s.alpha = alpha;
    s.rhoS = colour::Spectrum::constant(0.05);
    s.relief.width = s.width;
    s.relief.height = s.height;
    s.relief.pitchM = 0.001;
    s.relief.m.resize(static_cast<std::size_t>(s.width) * s.height);
    for (int y = 0; y < s.height; ++y) {
        const double v = (y + 0.5 - 0.5 * s.height) * 0.001;
        for (int x = 0; x < s.width; ++x) {
            s.relief.m[static_cast<std::size_t>(y) * s.width + x] =
                    std::sqrt(radiusM * radiusM - v * v);
        }
    }
    return s;
}

TEST(ReliefSpecularGrid, SpacingFollowsHowFastTheSurfaceTurnsAgainstTheLobe)
{
    // The cylinder's normal turns fastest at its outer rows, 78 mm from the crest:
    // turn = 1 mm / sqrt(R^2 - (78 mm)^2) (tests/unit/surface/relief_test.cpp checks that). The
    // specular grid is the largest power of two g <= 8 with 2 turn g <= 0.75 alpha.
    // The diffuse grid: the largest power of two g <= 8 with turn g <= 2 x 0.02 (two horizon
    // softnesses), whatever the gloss.
    struct Case {
        double radius, alpha;
        int grid, diffuseGrid;
    };
    for (const Case c : {
                 Case{0.15, 0.05, 2, 4}, // turn 0.00781: g <= 2.40; diffuse g <= 5.12
                 Case{0.30, 0.05, 4, 8}, // turn 0.00345: g <= 5.43; diffuse g <= 11.6
                 Case{0.50, 0.05, 8, 8}, // turn 0.00202: g <= 9.27, and 8 at most
                 Case{0.09, 0.05, 0, 1}, // turn 0.0223: even one texel is 0.84 of the reach;
                                         // diffuse g <= 1.79
                 Case{0.15, 0.20, 8, 4}, // a wider lobe: g <= 9.6
                 Case{0.15, 0.01, 0, 4}, // a mirror-like one: g <= 0.48
         }) {
        const surface::SurfaceScene scene = cylinderScene(c.radius, c.alpha);
        EXPECT_EQ(defaultSpecularGrid(scene), c.grid)
                << "radius " << c.radius << " alpha " << c.alpha;
        EXPECT_EQ(defaultDiffuseGrid(scene), c.diffuseGrid)
                << "radius " << c.radius << " alpha " << c.alpha;
    }
    // A plane is the flat case whatever its tilt.
    surface::SurfaceScene tilted = cylinderScene(0.15, 0.05);
    for (int y = 0; y < tilted.height; ++y) {
        for (int x = 0; x < tilted.width; ++x) {
            tilted.relief.m[static_cast<std::size_t>(y) * tilted.width + x] = 2e-4 * x + 1e-4 * y;
        }
    }
    ASSERT_FALSE(tilted.flat());
    EXPECT_EQ(defaultSpecularGrid(tilted), kFlatSpecularGrid);
    EXPECT_EQ(defaultDiffuseGrid(tilted), kFlatDiffuseGrid);
    // The shipped scenes: the ColorChecker flat, the painting's texel-sized relief per pixel, the
    // glossy cylinder (radius 15 cm, alpha 0.05) every 2 texels, its diffuse term every 4.
    struct Shipped {
        const char* name;
        int grid, diffuseGrid;
    };
    for (const Shipped c : {Shipped{"colorchecker", kFlatSpecularGrid, kFlatDiffuseGrid},
                            Shipped{"painting", 0, 0}, Shipped{"glossy-cylinder", 2, 4}}) {
        auto scene = surface::loadScene(dataDir() / "scenes" / c.name);
        ASSERT_TRUE(scene) << c.name;
        EXPECT_EQ(defaultSpecularGrid(*scene), c.grid) << c.name;
        EXPECT_EQ(defaultDiffuseGrid(*scene), c.diffuseGrid) << c.name;
    }
}

// What the glossy cylinder's grids (specular every 2 texels, diffuse every 4) cost where it
// counts: against the exact reference, at the panel's own density (the appliance shows its
// 240 x 160 texels on about 445 x 296 pixels), with the plan's D65 setting (128 point lights, 48
// samples). The interpolation's error is a property of each point, so a few hundred pixels at
// random, evaluated by the reference one by one, measure it as the whole frame would.
TEST(ReliefSpecularGrid, TheGlossyCylindersGridsStayNearPerPixelAgainstTheReference)
{
    auto obs = colour::loadCie1931(dataDir());
    auto booth = booth::loadBooth(dataDir() / "booth");
    auto scene = surface::loadScene(dataDir() / "scenes" / "glossy-cylinder");
    ASSERT_TRUE(obs && booth && scene);
    const booth::BoothLight& light = booth->lights[2]; // d65-fluorescent
    ASSERT_EQ(light.name, "d65-fluorescent");
    RenderSettings perPixel;
    perPixel.lights = 128;
    perPixel.specularSamples = 48;
    perPixel.specularGrid = 0;
    perPixel.diffuseGrid = 0;
    perPixel.areaLights = defaultAreaLights(*scene);
    ASSERT_FALSE(perPixel.areaLights);
    RenderSettings grid = perPixel;
    grid.specularGrid = defaultSpecularGrid(*scene);
    grid.diffuseGrid = defaultDiffuseGrid(*scene);
    ASSERT_EQ(grid.specularGrid, 2);
    ASSERT_EQ(grid.diffuseGrid, 4);
    // The appliance's basis, made for the light: what is left is the geometry's error.
    auto encoder = spectral::AdaptiveEncoder::createDefault(dataDir());
    ASSERT_TRUE(encoder) << encoder.error().message;
    auto basis = encoder->basisFor(light.spd);
    ASSERT_TRUE(basis) << basis.error().message;
    const PreparedScene ps = prepareScene(*scene, perPixel.horizonDirections, 0.01, *basis);
    const PreparedLight pl = prepareLight(light, *obs, perPixel.lights, *basis);
    struct Pose {
        Vec3 eye;
        double tiltDeg;
    };
    for (const Pose pose : {Pose{{0.0, 0.45, 0.60}, 30.0}, Pose{{0.25, 0.40, 0.55}, 10.0}}) {
        View view;
        view.panel = scene::panelPose(scene::degreesToRadians(pose.tiltDeg));
        view.eye = pose.eye;
        view.pixelsX = 444;
        view.pixelsY = 296;
        const XyzFrame a = renderRealtime(ps, pl, view, *obs, perPixel);
        const XyzFrame b = renderRealtime(ps, pl, view, *obs, grid);
        std::mt19937 rng(7);
        std::vector<std::pair<int, int>> pixels;
        std::vector<reference::SurfaceSample> points;
        for (int i = 0; i < 300; ++i) {
            const int px = std::uniform_int_distribution<int>(0, view.pixelsX - 1)(rng);
            const int py = std::uniform_int_distribution<int>(0, view.pixelsY - 1)(rng);
            pixels.emplace_back(px, py);
            points.push_back({(px + 0.5) / view.pixelsX, (py + 0.5) / view.pixelsY,
                              glm::dvec2((px + 0.5) * scene->width / view.pixelsX,
                                         (py + 0.5) * scene->height / view.pixelsY)});
        }
        const auto ref = reference::referenceAt(*scene, light, view, *obs, points);
        ASSERT_EQ(ref.xyz.size(), points.size());
        const auto errors = [&](const XyzFrame& f) {
            std::vector<double> e;
            for (std::size_t i = 0; i < points.size(); ++i) {
                const auto& px = f.xyz[static_cast<std::size_t>(pixels[i].second) * f.width +
                                       pixels[i].first];
                e.push_back(colour::ciede2000(colour::xyzToLab(ref.xyz[i], ref.whiteXyz),
                                              colour::xyzToLab(px, ref.whiteXyz)));
            }
            std::sort(e.begin(), e.end());
            return std::pair{e[static_cast<std::size_t>(0.95 * static_cast<double>(e.size() - 1))],
                             e.back()};
        };
        const auto [p95PerPixel, maxPerPixel] = errors(a);
        const auto [p95Grid, maxGrid] = errors(b);
        // The grid changes the frame (the specular term is there and interpolated) ...
        EXPECT_GT(reference::compareFrames(a, b).max, 0.05);
        // ... and stays near per-pixel shading, inside the budget.
        EXPECT_LE(p95Grid, p95PerPixel + 0.15) << "tilt " << pose.tiltDeg;
        EXPECT_LE(maxGrid, maxPerPixel + 0.5) << "tilt " << pose.tiltDeg;
        EXPECT_LE(p95Grid, 1.0);
        RecordProperty("tilt_" + std::to_string(static_cast<int>(pose.tiltDeg)) + "_p95",
                       std::to_string(p95PerPixel) + " per pixel, " + std::to_string(p95Grid) +
                               " grid");
        std::printf("tilt %.0f: p95 / max per pixel %.3f / %.3f, grids %d and %d %.3f / %.3f\n",
                    pose.tiltDeg, p95PerPixel, maxPerPixel, grid.specularGrid, grid.diffuseGrid,
                    p95Grid, maxGrid);
    }
}

} // namespace
} // namespace replica::pipeline::shading
