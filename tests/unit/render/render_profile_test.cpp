// Render profiles: each profile's switches are frozen (written out here as literals, so that an
// edit to the table fails), a new run records its profile's number alone, and every form an old
// recording holds (no keys, every key, some keys) reads back to the switches it was rendered with.
#include <set>
#include <string>

#include <nlohmann/json.hpp>

#include <pipeline/render/render_profile.h>
#include <platform/appliance.h>

#include <gtest/gtest.h>

namespace replica::pipeline::render {
namespace {

RenderSwitches allSwitches(bool on, double lodBias, bool surround, bool viewingFiltered)
{
    RenderSwitches s;
    s.hardwareFilter = on;
    s.specularNearestLevel = on;
    s.horizonSpread = on;
    s.horizonHalf = on;
    s.horizonBilinear = on;
    s.specularBranchFree = on;
    s.specularExactLevel = on;
    s.texelExactTies = on;
    s.horizonPick = on;
    s.specularLodBias = lodBias;
    s.surroundIlluminance = surround;
    s.viewingFiltered = viewingFiltered;
    return s;
}

// The profiles as they were frozen. A recording may hold any of these numbers: a change here is a
// change to what old recordings replay with, and must instead be a new profile.
const RenderSwitches kFrozen1 = allSwitches(false, 1.0, true, false);
const RenderSwitches kFrozen2 = allSwitches(true, 0.0, false, true);

TEST(RenderProfile, EachProfilesSwitchesAreFrozen)
{
    const auto profiles = renderProfiles();
    ASSERT_EQ(profiles.size(), 2u) << "a new profile: add its frozen switches to this test";
    EXPECT_EQ(profiles[0].switches, kFrozen1);
    EXPECT_EQ(profiles[1].switches, kFrozen2);
    std::set<std::string> names;
    for (std::size_t i = 0; i < profiles.size(); ++i) {
        EXPECT_EQ(profiles[i].number, static_cast<int>(i) + 1);
        EXPECT_TRUE(names.insert(profiles[i].name).second) << profiles[i].name;
        EXPECT_GT(std::string(profiles[i].summary).size(), 40u) << "document what it fixes";
        for (std::size_t k = 0; k < i; ++k) {
            EXPECT_FALSE(profiles[i].switches == profiles[k].switches)
                    << "profiles " << k + 1 << " and " << i + 1 << " are the same";
        }
    }
    EXPECT_EQ(kCurrentRenderProfile, 2);
    EXPECT_EQ(currentRenderSwitches(), kFrozen2);
    // The legacy bias the first profile holds is the renderer's bias of then.
    EXPECT_EQ(kFrozen1.specularLodBias, shading::kLegacySpecularLodBias);
}

TEST(RenderProfile, EveryFieldTakesPartInTheComparison)
{
    // A switch left out of operator== (or of the match) would let two profiles compare equal.
    const RenderSwitches base = kFrozen2;
    bool RenderSwitches::*const flags[] = {
            &RenderSwitches::hardwareFilter,     &RenderSwitches::specularNearestLevel,
            &RenderSwitches::horizonSpread,      &RenderSwitches::horizonHalf,
            &RenderSwitches::horizonBilinear,    &RenderSwitches::specularBranchFree,
            &RenderSwitches::specularExactLevel, &RenderSwitches::texelExactTies,
            &RenderSwitches::horizonPick,        &RenderSwitches::surroundIlluminance,
            &RenderSwitches::viewingFiltered};
    for (const auto flag : flags) {
        RenderSwitches s = base;
        s.*flag = !(s.*flag);
        EXPECT_FALSE(s == base);
        EXPECT_EQ(matchRenderProfile(s), kExplicitRenderProfile);
    }
    RenderSwitches s = base;
    s.specularLodBias = 0.5;
    EXPECT_EQ(matchRenderProfile(s), kExplicitRenderProfile);
    EXPECT_EQ(matchRenderProfile(kFrozen1), 1);
    EXPECT_EQ(matchRenderProfile(kFrozen2), 2);
}

TEST(RenderProfile, SwitchesReachTheRenderSettings)
{
    for (const RenderSwitches& sw : {kFrozen1, kFrozen2}) {
        shading::RenderSettings s;
        applyRenderSwitches(sw, s);
        EXPECT_EQ(s.hardwareFilter, sw.hardwareFilter);
        EXPECT_EQ(s.specularNearestLevel, sw.specularNearestLevel);
        EXPECT_EQ(s.horizonSpread, sw.horizonSpread);
        EXPECT_EQ(s.horizonHalf, sw.horizonHalf);
        EXPECT_EQ(s.horizonBilinear, sw.horizonBilinear);
        EXPECT_EQ(s.specularBranchFree, sw.specularBranchFree);
        EXPECT_EQ(s.specularExactLevel, sw.specularExactLevel);
        EXPECT_EQ(s.texelExactTies, sw.texelExactTies);
        EXPECT_EQ(s.horizonPick, sw.horizonPick);
        EXPECT_EQ(s.specularLodBias, sw.specularLodBias);
    }
}

TEST(RenderProfile, UnknownNumbersAreRefusedByName)
{
    EXPECT_TRUE(findRenderProfile(1));
    EXPECT_TRUE(findRenderProfile(2));
    for (const int n : {-1, 0, 3, 99}) {
        const auto p = findRenderProfile(n);
        ASSERT_FALSE(p) << n;
        EXPECT_NE(p.error().message.find("render profile " + std::to_string(n)), std::string::npos)
                << p.error().message;
    }
}

const char* const kSwitchKeys[] = {
        "hardware_filter",  "specular_lod_bias", "specular_nearest_level", "horizon_spread",
        "horizon_half",     "horizon_bilinear",  "specular_branch_free",   "specular_exact_level",
        "texel_exact_ties", "horizon_pick",      "surround_illuminance",   "viewing_filtered"};

TEST(RenderProfile, NewRunsRecordTheProfileNumberAlone)
{
    const platform::RunConfig c;
    EXPECT_EQ(c.renderProfile(), kCurrentRenderProfile);
    const auto j = nlohmann::json::parse(c.toJson());
    EXPECT_EQ(j.at("render_profile").get<int>(), kCurrentRenderProfile);
    for (const char* key : kSwitchKeys) {
        EXPECT_FALSE(j.contains(key)) << key;
    }
    const auto back = platform::RunConfig::fromJson(c.toJson());
    ASSERT_TRUE(back) << back.error().message;
    EXPECT_EQ(back->switches, kFrozen2);
}

TEST(RenderProfile, OldRecordingsMapOntoTheirProfileOrStayExplicit)
{
    platform::RunConfig c;
    auto j = nlohmann::json::parse(c.toJson());
    j.erase("render_profile");
    // Made before the switches: no keys at all (recordings/samples/walk-v1..v3) -> profile 1.
    {
        const auto o = platform::RunConfig::fromJson(j.dump());
        ASSERT_TRUE(o) << o.error().message;
        EXPECT_EQ(o->switches, kFrozen1);
        EXPECT_EQ(o->renderProfile(), 1);
    }
    // Made with every key, at the defaults of 2026-12-03 (walk-v4, the renderer goldens, the boot
    // recording) -> profile 2.
    auto all = j;
    all["hardware_filter"] = true;
    all["specular_lod_bias"] = 0.0;
    all["specular_nearest_level"] = true;
    all["horizon_spread"] = true;
    all["horizon_half"] = true;
    all["horizon_bilinear"] = true;
    all["specular_branch_free"] = true;
    all["specular_exact_level"] = true;
    all["texel_exact_ties"] = true;
    all["horizon_pick"] = true;
    all["surround_illuminance"] = false;
    all["viewing_filtered"] = true;
    {
        const auto o = platform::RunConfig::fromJson(all.dump());
        ASSERT_TRUE(o) << o.error().message;
        EXPECT_EQ(o->switches, kFrozen2);
        EXPECT_EQ(o->renderProfile(), 2);
    }
    // Some keys only (a build between two switches): explicit, and written back key by key.
    auto some = j;
    some["hardware_filter"] = true;
    some["specular_nearest_level"] = true;
    {
        const auto o = platform::RunConfig::fromJson(some.dump());
        ASSERT_TRUE(o) << o.error().message;
        EXPECT_TRUE(o->switches.hardwareFilter);
        EXPECT_TRUE(o->switches.specularNearestLevel);
        EXPECT_FALSE(o->switches.horizonPick);
        EXPECT_EQ(o->switches.specularLodBias, 1.0);
        EXPECT_EQ(o->renderProfile(), kExplicitRenderProfile);
        const auto written = nlohmann::json::parse(o->toJson());
        EXPECT_EQ(written.at("render_profile").get<int>(), kExplicitRenderProfile);
        for (const char* key : kSwitchKeys) {
            EXPECT_TRUE(written.contains(key)) << key;
        }
        const auto again = platform::RunConfig::fromJson(o->toJson());
        ASSERT_TRUE(again);
        EXPECT_EQ(again->switches, o->switches);
    }
}

TEST(RenderProfile, ConflictingOrUnknownProfilesAreRefused)
{
    platform::RunConfig c;
    auto j = nlohmann::json::parse(c.toJson());
    j["render_profile"] = 7;
    const auto unknown = platform::RunConfig::fromJson(j.dump());
    ASSERT_FALSE(unknown);
    EXPECT_NE(unknown.error().message.find("render profile 7 is not known"), std::string::npos)
            << unknown.error().message;
    j["render_profile"] = 2;
    j["horizon_pick"] = false;
    const auto both = platform::RunConfig::fromJson(j.dump());
    ASSERT_FALSE(both);
    EXPECT_NE(both.error().message.find("horizon_pick"), std::string::npos) << both.error().message;
}

} // namespace
} // namespace replica::pipeline::render
