// booth.json + EXR round trip and the messages for broken booth folders.
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include <pipeline/booth/booth_model.h>
#include <pipeline/image/exr.h>

#include <gtest/gtest.h>

#include "../render/render_fixtures.h"

namespace replica::pipeline::booth {
namespace {

std::filesystem::path freshDir(const std::string& name)
{
    auto d = std::filesystem::temp_directory_path() / ("replica_booth_test_" + name);
    std::filesystem::remove_all(d);
    return d;
}

TEST(BoothModel, RoundTripsThroughJsonAndExr)
{
    Booth b;
    b.lights.push_back(test::stripedLight(40, 20));
    b.lights[0].name = "d50";
    b.lights[0].spd[5] = 7.0;
    const auto dir = freshDir("roundtrip");
    ASSERT_TRUE(saveBooth(dir, b));
    auto r = loadBooth(dir);
    ASSERT_TRUE(r) << r.error().message;
    ASSERT_EQ(r->lights.size(), 1u);
    const BoothLight& l = r->lights[0];
    EXPECT_EQ(l.name, "d50");
    EXPECT_EQ(l.luminance.width, 40);
    EXPECT_EQ(l.spd[5], 7.0);
    EXPECT_EQ(l.centre, b.lights[0].centre);
    for (std::size_t k = 0; k < l.luminance.cdM2.size(); ++k) {
        EXPECT_FLOAT_EQ(static_cast<float>(l.luminance.cdM2[k]),
                        static_cast<float>(b.lights[0].luminance.cdM2[k]));
    }
    EXPECT_NE(r->find("d50"), nullptr);
    EXPECT_EQ(r->find("nope"), nullptr);
}

TEST(BoothModel, WallsAreDeclaredOrNotModelled)
{
    Booth b;
    b.lights.push_back(test::stripedLight(8, 4));
    const auto dir = freshDir("walls");
    ASSERT_TRUE(saveBooth(dir, b));
    auto none = loadBooth(dir);
    ASSERT_TRUE(none) << none.error().message;
    EXPECT_FALSE(none->walls.has_value()); // no "walls": not modelled
    BoothWalls w;
    w.reflectance = colour::Spectrum::constant(0.2);
    w.reflectance[3] = 0.6;
    b.walls = w;
    ASSERT_TRUE(saveBooth(dir, b));
    auto with = loadBooth(dir);
    ASSERT_TRUE(with) << with.error().message;
    ASSERT_TRUE(with->walls.has_value());
    EXPECT_EQ(with->walls->reflectance[3], 0.6);
    EXPECT_EQ(with->walls->reflectance[4], 0.2);
    // "walls": {} is N7 (booth.json's keys are sorted: "walls" comes last).
    {
        std::ifstream in(dir / "booth.json");
        std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
        const auto at = text.find("\"walls\"");
        ASSERT_NE(at, std::string::npos);
        text = text.substr(0, at) + "\"walls\": {}\n}\n";
        std::ofstream(dir / "booth.json") << text;
    }
    auto n7 = loadBooth(dir);
    ASSERT_TRUE(n7) << n7.error().message;
    ASSERT_TRUE(n7->walls.has_value());
    EXPECT_EQ(n7->walls->reflectance[0], kMunsellN7Reflectance);
}

TEST(BoothModel, RefusesAnEmptyOrRepeatedLampName)
{
    Booth b;
    b.lights.push_back(test::ceilingLight(8, 4, 500.0));
    b.lights.push_back(test::ceilingLight(8, 4, 700.0));
    b.lights[0].name = "tungsten";
    b.lights[1].name = "d65";
    const auto dir = freshDir("names");
    ASSERT_TRUE(saveBooth(dir, b));
    std::ifstream in(dir / "booth.json");
    const std::string text{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
    ASSERT_TRUE(loadBooth(dir));
    // The second lamp renamed to the first's (its map still d65.exr), then to nothing.
    for (const auto& [name, expected] :
         {std::pair<std::string, std::string>{"tungsten",
                                              "lights[1].name: 'tungsten' names another "
                                              "lamp of this booth too"},
          {"", "lights[1].name: is empty"}}) {
        std::string edited = text;
        const auto at = edited.find("\"d65\"");
        ASSERT_NE(at, std::string::npos);
        edited.replace(at, 5, "\"" + name + "\"");
        std::ofstream(dir / "booth.json", std::ios::trunc) << edited;
        auto r = loadBooth(dir);
        ASSERT_FALSE(r) << name;
        EXPECT_NE(r.error().message.find(expected), std::string::npos) << r.error().message;
    }
}

TEST(BoothModel, ReportsMissingFolderAndBadFields)
{
    auto r = loadBooth(freshDir("missing"));
    ASSERT_FALSE(r);
    EXPECT_NE(r.error().message.find("booth.json: cannot open"), std::string::npos)
            << r.error().message;

    const auto dir = freshDir("badfield");
    std::filesystem::create_directories(dir);
    std::ofstream(dir / "booth.json")
            << R"({"format":"replica-booth/1","lights":[{"name":"a","luminance":"a.exr",
        "centre":[0,1],"edge_u":[1,0,0],"edge_v":[0,0,1],"spd":[]}]})";
    r = loadBooth(dir);
    ASSERT_FALSE(r);
    // Held against the written schema first: the message names the JSON path.
    EXPECT_NE(r.error().message.find("booth.json: /lights/0/centre: expected an array of 3 items, "
                                     "found 2"),
              std::string::npos)
            << r.error().message;

    std::ofstream(dir / "booth.json") << "{ not json";
    r = loadBooth(dir);
    ASSERT_FALSE(r);
    EXPECT_NE(r.error().message.find("not valid JSON"), std::string::npos);
}

TEST(BoothModel, RejectsNanInTheLuminanceExrNamingThePixel)
{
    Booth b;
    b.lights.push_back(test::ceilingLight(8, 4, 100.0));
    const auto dir = freshDir("nan");
    ASSERT_TRUE(saveBooth(dir, b));
    image::ChannelImage img;
    img.width = 8;
    img.height = 4;
    img.names = {"Y"};
    img.planes.assign(1, std::vector<float>(32, 100.0f));
    img.planes[0][2 * 8 + 5] = std::numeric_limits<float>::quiet_NaN();
    ASSERT_TRUE(image::writeExr(dir / "test.exr", img));
    auto r = loadBooth(dir);
    ASSERT_FALSE(r);
    EXPECT_NE(r.error().message.find("test.exr: channel 'Y' pixel (5, 2) is nan"),
              std::string::npos)
            << r.error().message;
}

TEST(BoothLight, GeometryAndUnitSpd)
{
    const BoothLight l = test::ceilingLight(100, 50, 1.0);
    EXPECT_NEAR(l.normal().y, -1.0, 1e-15);
    EXPECT_NEAR(l.texelAreaM2(), 0.5 / 5000.0, 1e-18);
    EXPECT_NEAR(l.pointAtTexel(0, 0).x, -0.5, 1e-15);
    EXPECT_NEAR(l.pointAtTexel(100, 50).z, 0.25, 1e-15);
    const auto unit = unitLuminanceSpd(test::observer(), l.spd);
    EXPECT_NEAR(colour::spectrumToXyz(test::observer(), unit).y, 1.0, 1e-12);
    EXPECT_EQ(unitLuminanceSpd(test::observer(), colour::Spectrum{}).max(), 0.0);
}

} // namespace
} // namespace replica::pipeline::booth
