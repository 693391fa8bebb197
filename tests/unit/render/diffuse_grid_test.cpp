// The diffuse grid of the CPU model (RenderSettings::diffuseGrid): what summing eq. (1) at the
// grid's nodes and interpolating costs the flat scenes against summing it per pixel, and that
// relief ignores it.
#include <algorithm>

#include <pipeline/base/data_dir.h>
#include <pipeline/booth/booth_model.h>
#include <pipeline/reference/frame_error.h>
#include <pipeline/shading/realtime_model.h>

#include <gtest/gtest.h>

namespace replica::pipeline::shading {
namespace {

TEST(DiffuseGrid, CostsTheFlatScenesAHundredthOfADeltaE00UnderEveryLight)
{
    auto obs = colour::loadCie1931(dataDir());
    auto booth = booth::loadBooth(dataDir() / "booth");
    ASSERT_TRUE(obs && booth);
    double worstMax = 0.0;
    double worstP95 = 0.0;
    for (const char* name : {"colorchecker", "metamer"}) {
        auto scene = surface::loadScene(dataDir() / "scenes" / name);
        ASSERT_TRUE(scene) << scene.error().message;
        ASSERT_EQ(defaultDiffuseGrid(*scene), kFlatDiffuseGrid);
        RenderSettings perPixel;
        perPixel.specularPass = false; // the diffuse term alone: nothing else differs
        RenderSettings grid = perPixel;
        grid.diffuseGrid = kFlatDiffuseGrid;
        const PreparedScene ps = prepareScene(*scene, perPixel.horizonDirections);
        for (const auto& light : booth->lights) {
            const PreparedLight pl = prepareLight(light, *obs, perPixel.lights);
            // Small tilts put the ceiling's lights nearest the surface's top edge and at grazing
            // angles: where the illuminance bends most over the surface.
            for (const double tilt : {5.0, 30.0, 60.0}) {
                View view;
                view.panel = scene::panelPose(scene::degreesToRadians(tilt));
                view.pixelsX = 96;
                view.pixelsY = 64;
                const XyzFrame a = renderRealtime(ps, pl, view, *obs, perPixel);
                const XyzFrame b = renderRealtime(ps, pl, view, *obs, grid);
                const reference::FrameError e = reference::compareFrames(a, b);
                EXPECT_GT(e.max, 0.0) << name << ", " << light.name << ", " << tilt; // not off
                worstMax = std::max(worstMax, e.max);
                worstP95 = std::max(worstP95, e.p95);
            }
        }
    }
    EXPECT_LE(worstMax, 0.01);
    RecordProperty("worst_p95", std::to_string(worstP95));
    RecordProperty("worst_max", std::to_string(worstMax));
}

TEST(DiffuseGrid, ReliefIsSummedPerPixelWhateverTheSetting)
{
    auto obs = colour::loadCie1931(dataDir());
    auto booth = booth::loadBooth(dataDir() / "booth");
    auto scene = surface::loadScene(dataDir() / "scenes" / "painting");
    ASSERT_TRUE(obs && booth && scene);
    EXPECT_EQ(defaultDiffuseGrid(*scene), 0);
    RenderSettings perPixel;
    perPixel.specularSamples = 4;
    RenderSettings grid = perPixel;
    grid.diffuseGrid = kFlatDiffuseGrid;
    View view;
    view.pixelsX = 32;
    view.pixelsY = 24;
    const PreparedScene ps = prepareScene(*scene, perPixel.horizonDirections);
    const PreparedLight pl = prepareLight(booth->lights[0], *obs, perPixel.lights);
    const XyzFrame a = renderRealtime(ps, pl, view, *obs, perPixel);
    const XyzFrame b = renderRealtime(ps, pl, view, *obs, grid);
    ASSERT_EQ(a.xyz.size(), b.xyz.size());
    for (std::size_t i = 0; i < a.xyz.size(); ++i) {
        ASSERT_EQ(a.xyz[i], b.xyz[i]) << i;
    }
}

} // namespace
} // namespace replica::pipeline::shading
