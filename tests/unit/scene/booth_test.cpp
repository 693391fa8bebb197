// The appliance's booth (scene::Booth) and the booth model (data/booth) are one booth: the same
// ceiling for the flat renderer, pass 2's flare and the booth renderer.
#include <filesystem>

#include <glm/geometric.hpp>

#include <pipeline/base/data_dir.h>
#include <pipeline/booth/booth_generator.h>
#include <pipeline/booth/booth_model.h>
#include <pipeline/scene/booth.h>

#include <gtest/gtest.h>

namespace replica::pipeline::scene {
namespace {

TEST(DefaultBooth, HasTheBoothModelsCeiling)
{
    auto b = loadDefaultBooth(dataDir().string());
    ASSERT_TRUE(b) << b.error().message;
    auto model = booth::loadBooth(dataDir() / "booth");
    ASSERT_TRUE(model) << model.error().message;
    ASSERT_FALSE(model->lights.empty());
    for (const auto& l : model->lights) {
        EXPECT_EQ(b->emitter.centreM, l.centre) << l.name;
        EXPECT_EQ(b->emitter.edgeUM, l.edgeU) << l.name;
        EXPECT_EQ(b->emitter.edgeVM, l.edgeV) << l.name;
        EXPECT_EQ(b->emitter.normal, l.normal()) << l.name;
        // Every lamp of the appliance has its light in the model.
    }
    for (const auto& lamp : b->lamps) {
        EXPECT_NE(model->find(lamp.name), nullptr) << lamp.name;
    }
    // The generator that made data/booth and the built-in default agree too.
    const booth::CeilingGeometry g;
    const Emitter e;
    EXPECT_EQ(e.centreM, g.centre);
    EXPECT_DOUBLE_EQ(glm::length(e.edgeUM), g.widthM);
    EXPECT_DOUBLE_EQ(glm::length(e.edgeVM), g.depthM);
    EXPECT_EQ(e.centreM, b->emitter.centreM);
    EXPECT_EQ(e.edgeUM, b->emitter.edgeUM);
    EXPECT_EQ(e.edgeVM, b->emitter.edgeVM);
    // Emits downwards into the booth.
    EXPECT_DOUBLE_EQ(b->emitter.normal.y, -1.0);
}

TEST(DefaultBooth, TheUniformGridTilesTheCeilingWithItsPower)
{
    // 4 x 2 cells of a 1 x 0.5 m emitter at 2000 cd/m^2: each light L * a = 2000 * 0.0625 cd at
    // its cell's centre; the cells' rectangles tile the emitter.
    Emitter e;
    const auto lights = uniformGridLights(e, 2000.0, 4, 2);
    ASSERT_EQ(lights.size(), 8u);
    double power = 0.0;
    for (const auto& l : lights) {
        EXPECT_NEAR(l.intensityCd, 2000.0 * 1.0 * 0.5 / 8.0, 1e-12);
        EXPECT_EQ(l.meanCdM2, 2000.0);
        EXPECT_NEAR(glm::length(l.regionU), 0.25, 1e-15);
        EXPECT_NEAR(glm::length(l.regionV), 0.25, 1e-15);
        EXPECT_NEAR(glm::length(l.regionOrigin + 0.5 * (l.regionU + l.regionV) - l.position), 0.0,
                    1e-15);
        power += l.intensityCd;
    }
    EXPECT_NEAR(power, 2000.0 * 0.5, 1e-9);
    // The first cell's centre: the emitter's corner plus half a cell along each edge.
    EXPECT_NEAR(glm::length(lights[0].position - (e.centreM + glm::dvec3(-0.375, 0.0, -0.125))),
                0.0, 1e-15);
}

TEST(DefaultBooth, RefusesAModelWhoseLightsHaveTwoCeilings)
{
    const auto dir = std::filesystem::temp_directory_path() / "replica_two_ceilings";
    std::filesystem::remove_all(dir);
    std::filesystem::create_directories(dir);
    std::filesystem::copy(dataDir() / "spectra", dir / "spectra");
    auto model = booth::loadBooth(dataDir() / "booth");
    ASSERT_TRUE(model);
    model->lights.back().centre.y += 0.1;
    ASSERT_TRUE(booth::saveBooth(dir / "booth", *model));
    auto b = loadDefaultBooth(dir.string());
    ASSERT_FALSE(b);
    EXPECT_NE(b.error().message.find("booth.json: light 'd65-fluorescent' has another ceiling"),
              std::string::npos)
            << b.error().message;
    std::filesystem::remove_all(dir);
}

} // namespace
} // namespace replica::pipeline::scene
