// The appliance's booth is the booth model (data/booth) with its lamps' reference spectra and
// nominal luminances: one ceiling, the one emitter of every lamp.
#include <filesystem>

#include <glm/geometric.hpp>

#include <pipeline/base/data_dir.h>
#include <pipeline/booth/booth_model.h>
#include <pipeline/offline/booth/booth_generator.h>
#include <pipeline/scene/booth.h>

#include <gtest/gtest.h>

namespace replica::pipeline::scene {
namespace {

TEST(DefaultBooth, IsTheBoothModelWithItsLampsInTheModelsOrder)
{
    auto b = loadDefaultBooth(dataDir().string());
    ASSERT_TRUE(b) << b.error().message;
    auto model = booth::loadBooth(dataDir() / "booth");
    ASSERT_TRUE(model) << model.error().message;
    EXPECT_EQ(b->id, "replica-booth-1");
    // The lamp index is the index into booth.json's lights: tungsten, d50, d65.
    ASSERT_EQ(b->lights.size(), 3u);
    ASSERT_EQ(model->lights.size(), b->lights.size());
    EXPECT_EQ(b->lights[0].name, "tungsten");
    EXPECT_EQ(b->lights[1].name, "d50-fluorescent");
    EXPECT_EQ(b->lights[2].name, "d65-fluorescent");
    for (std::size_t i = 0; i < b->lights.size(); ++i) {
        const auto& l = b->lights[i];
        const auto& m = model->lights[i];
        EXPECT_EQ(l.name, m.name);
        EXPECT_EQ(l.centre, m.centre) << l.name;
        EXPECT_EQ(l.edgeU, m.edgeU) << l.name;
        EXPECT_EQ(l.edgeV, m.edgeV) << l.name;
        EXPECT_EQ(l.spd.v, m.spd.v) << l.name;
        EXPECT_EQ(l.luminance.cdM2, m.luminance.cdM2) << l.name;
        // booth.json holds no lamp fields; the default booth fills them by name.
        EXPECT_EQ(m.nominalLuminanceCdM2, 0.0);
        EXPECT_GT(l.referenceSpectrum.sum(), 0.0) << l.name;
    }
    // Nominal luminances: tungsten 2200, the fluorescent simulators 2600 cd/m^2; the luminance
    // images of the shipped model (booth_generator.cpp) are scaled to these means.
    EXPECT_EQ(b->lights[0].nominalLuminanceCdM2, 2200.0);
    EXPECT_EQ(b->lights[1].nominalLuminanceCdM2, 2600.0);
    EXPECT_EQ(b->lights[2].nominalLuminanceCdM2, 2600.0);
    for (const auto& l : b->lights) {
        const double mean = l.luminance.sum() / static_cast<double>(l.luminance.cdM2.size());
        EXPECT_NEAR(mean, l.nominalLuminanceCdM2, 1e-3 * l.nominalLuminanceCdM2) << l.name;
    }
    // Reference spectra by name: CIE A rises through the visible (tungsten, 2856 K: S(730) /
    // S(380) is 216.1 / 9.8 = 22 in the CIE table).
    const auto& a = b->lights[0].referenceSpectrum;
    EXPECT_GT(a.v.back() / a.v.front(), 20.0);
    EXPECT_LT(a.v.back() / a.v.front(), 30.0);
    EXPECT_EQ(b->lights[0].referenceColumn, "A");
    EXPECT_EQ(b->lights[1].referenceColumn, "F8");
    EXPECT_EQ(b->lights[2].referenceColumn, "F7");
    // The reference spectrum is not the booth model's own SPD: both stay, for different uses.
    EXPECT_NE(b->lights[1].referenceSpectrum.v, b->lights[1].spd.v);
    // One ceiling, the generator's, emitting downwards into the booth.
    const booth::CeilingGeometry g;
    const auto& c = b->ceiling();
    EXPECT_EQ(c.centre, g.centre);
    EXPECT_DOUBLE_EQ(glm::length(c.edgeU), g.widthM);
    EXPECT_DOUBLE_EQ(glm::length(c.edgeV), g.depthM);
    EXPECT_DOUBLE_EQ(c.normal().y, -1.0);
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

TEST(DefaultBooth, RefusesALightThatIsNotAKnownLamp)
{
    const auto dir = std::filesystem::temp_directory_path() / "replica_unknown_lamp";
    std::filesystem::remove_all(dir);
    std::filesystem::create_directories(dir);
    std::filesystem::copy(dataDir() / "spectra", dir / "spectra");
    auto model = booth::loadBooth(dataDir() / "booth");
    ASSERT_TRUE(model);
    model->lights[1].name = "neon";
    ASSERT_TRUE(booth::saveBooth(dir / "booth", *model));
    auto b = loadDefaultBooth(dir.string());
    ASSERT_FALSE(b);
    EXPECT_NE(b.error().message.find("booth.json: light 'neon' is not a lamp this build knows"),
              std::string::npos)
            << b.error().message;
    std::filesystem::remove_all(dir);
}

} // namespace
} // namespace replica::pipeline::scene
