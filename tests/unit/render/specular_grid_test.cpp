// The specular grid of the CPU model (shading::gridNodes, gridValue): node layout,
// interpolation that is exact for bilinear functions, and what the grid costs the ColorChecker
// against shading the specular term per pixel.
#include <cmath>

#include <pipeline/base/data_dir.h>
#include <pipeline/booth/booth_model.h>
#include <pipeline/reference/frame_error.h>
#include <pipeline/shading/realtime_model.h>

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

} // namespace
} // namespace replica::pipeline::shading
