// The run configuration's light ("auto" | "direct"), direct-sensor level and booth folder: recorded
// like any setting, and a recording made before them replays as it was (auto, the booth's mean
// luminance, the shipped booth unchecked).
#include <nlohmann/json.hpp>

#include <platform/appliance.h>

#include <gtest/gtest.h>

namespace replica::platform {
namespace {

TEST(RunConfigLightBooth, RoundTripsAndOlderRecordingsReadAsBefore)
{
    RunConfig c;
    c.light = kLightDirect;
    c.directCdM2PerY = 0.75;
    c.boothDir = "/srv/booth";
    c.boothDigest = "0123456789abcdef";
    auto back = RunConfig::fromJson(c.toJson());
    ASSERT_TRUE(back) << back.error().message;
    EXPECT_EQ(back->light, kLightDirect);
    EXPECT_EQ(back->directCdM2PerY, 0.75);
    EXPECT_EQ(back->boothDir, "/srv/booth");
    EXPECT_EQ(back->boothDigest, "0123456789abcdef");

    auto j = nlohmann::json::parse(c.toJson());
    j.erase("light");
    j.erase("booth_dir");
    j.erase("booth_digest");
    j["sensing"].erase("direct_cdm2_per_y");
    auto old = RunConfig::fromJson(j.dump());
    ASSERT_TRUE(old) << old.error().message;
    EXPECT_EQ(old->light, kLightAuto);
    EXPECT_EQ(old->directCdM2PerY, 0.0); // the booth's mean luminance, as then
    EXPECT_EQ(old->boothDir, "booth");
    EXPECT_EQ(old->boothDigest, "");
    j.erase("sensing");
    old = RunConfig::fromJson(j.dump());
    ASSERT_TRUE(old) << old.error().message;
    EXPECT_EQ(old->directCdM2PerY, 0.0);
}

TEST(RunConfigLightBooth, BadValuesAreRefused)
{
    auto j = nlohmann::json::parse(RunConfig{}.toJson());
    j["light"] = "sideways";
    auto r = RunConfig::fromJson(j.dump());
    ASSERT_FALSE(r);
    EXPECT_NE(r.error().message.find("light 'sideways' is not 'auto' or 'direct'"),
              std::string::npos)
            << r.error().message;
    j = nlohmann::json::parse(RunConfig{}.toJson());
    j["sensing"]["direct_cdm2_per_y"] = -1.0;
    EXPECT_FALSE(RunConfig::fromJson(j.dump()));
    j = nlohmann::json::parse(RunConfig{}.toJson());
    j["booth_dir"] = 7;
    EXPECT_FALSE(RunConfig::fromJson(j.dump()));
}

TEST(RunConfigLightBooth, ARecordedBoothOutsideTheDataFoldersOrWithDotsIsRefused)
{
    RunConfig c;
    c.sceneDigest = "0123456789abcdef";
    c.displayDigest = "0123456789abcdef";
    c.boothDir = "../../etc";
    auto ok = checkRecordedReferences(c, {}, false);
    ASSERT_FALSE(ok);
    EXPECT_NE(ok.error().message.find("booth_dir"), std::string::npos) << ok.error().message;
    c.boothDir = "/etc";
    ok = checkRecordedReferences(c, {}, false);
    ASSERT_FALSE(ok);
    EXPECT_NE(ok.error().message.find("--data-root"), std::string::npos) << ok.error().message;
    c.boothDir = "booth";
    EXPECT_TRUE(checkRecordedReferences(c, {}, false));
}

} // namespace
} // namespace replica::platform
