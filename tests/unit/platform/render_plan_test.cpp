// The planner's plan file: what renderPlanJson writes reads back to the same choice, and the
// reader refuses every malformed field with a line naming the file and the field. The plans
// shipped with the scenes are current (their digests are the scene's, booth's and basis's of
// today, so 'replica run' finds them) and a scene without a plan is not planned unasked.
#include <filesystem>
#include <string>

#include <nlohmann/json.hpp>

#include <pipeline/base/data_dir.h>
#include <platform/appliance.h>
#include <platform/render_plan.h>

#include <gtest/gtest.h>

namespace replica::tests {
namespace {

using namespace platform;

RenderPlan samplePlan()
{
    RenderPlan p;
    p.sceneDigest = "0123456789abcdef";
    p.boothDigest = "fedcba9876543210";
    p.basis = "adaptive_k6";
    p.lamps["tungsten"] = {16, 8, 8, 0.886, 1.981, true, true};
    p.lamps["d65-fluorescent"] = {32, 4, 8, 0.789, 2.309, true, false};
    return p;
}

TEST(RenderPlan, RoundTripsEveryLampsChoice)
{
    const RenderPlan p = samplePlan();
    auto back = parseRenderPlan(renderPlanJson(p), "plan.json");
    ASSERT_TRUE(back) << back.error().message;
    EXPECT_EQ(back->sceneDigest, p.sceneDigest);
    EXPECT_EQ(back->boothDigest, p.boothDigest);
    EXPECT_EQ(back->basis, p.basis);
    ASSERT_EQ(back->lamps.size(), 2u);
    EXPECT_EQ(back->lamps.at("tungsten").lights, 16);
    EXPECT_EQ(back->lamps.at("tungsten").specularSamples, 8);
    EXPECT_EQ(back->lamps.at("d65-fluorescent").lights, 32);
    EXPECT_EQ(back->lamps.at("d65-fluorescent").specularSamples, 4);
    EXPECT_DOUBLE_EQ(back->lamps.at("tungsten").probeMax, 1.981);
    EXPECT_TRUE(back->lamps.at("tungsten").walls);
    EXPECT_FALSE(back->lamps.at("d65-fluorescent").walls);
}

TEST(RenderPlan, APlanThatDoesNotSayDrawsTheBoothsWalls)
{
    // Plans written before the planner chose the walls: a booth with walls drew them for every
    // lamp, so an absent "walls" keeps them.
    auto j = nlohmann::json::parse(renderPlanJson(samplePlan()));
    for (auto& [name, lamp] : j["lamps"].items()) {
        ASSERT_EQ(lamp.erase("walls"), 1u) << name;
    }
    const std::string text = j.dump(2);
    auto back = parseRenderPlan(text, "old-plan.json");
    ASSERT_TRUE(back) << back.error().message;
    for (const auto& [name, p] : back->lamps) {
        EXPECT_TRUE(p.walls) << name;
    }
}

TEST(RenderPlan, RefusesMalformedFilesNamingThem)
{
    const std::string good = renderPlanJson(samplePlan());
    const auto refused = [](const std::string& text, const std::string& names) {
        auto r = parseRenderPlan(text, "/cache/plan-x.json");
        ASSERT_FALSE(r) << "accepted: " << text;
        EXPECT_NE(r.error().message.find("/cache/plan-x.json"), std::string::npos)
                << r.error().message;
        EXPECT_NE(r.error().message.find(names), std::string::npos) << r.error().message;
    };
    const auto replaced = [&](const std::string& from, const std::string& to) {
        std::string s = good;
        const auto at = s.find(from);
        EXPECT_NE(at, std::string::npos) << from;
        return s.replace(at, from.size(), to);
    };
    refused("{\"format\": ", "not JSON");
    refused("[]", "format");
    refused(replaced("replica-plan/1", "replica-plan/2"), "format");
    refused(replaced("\"lights\": 32", "\"lights\": 0"), "lights");
    refused(replaced("\"lights\": 32", "\"lights\": 257"), "lights");
    refused(replaced("\"lights\": 32", "\"lights\": 8.5"), "lights");
    refused(replaced("\"specular_samples\": 4", "\"specular_samples\": -1"), "specular_samples");
    refused(replaced("\"horizon_directions\": 8", "\"horizon_directions\": 33"),
            "horizon_directions");
    refused(replaced("\"basis\": \"adaptive_k6\"", "\"basis\": 6"), "basis");
    refused(replaced("\"walls\": false", "\"walls\": 0"), "walls");
    refused(replaced("\"walls\": false", "\"walls\": \"no\""), "walls");
    std::string noLamps = good.substr(0, good.find("\"lamps\"")) +
                          "\"lamps\": {}, \"scene_digest\": \"0123456789abcdef\"}";
    refused(noLamps, "lamps");
}

TEST(RenderPlan, EveryShippedSceneCarriesItsCurrentPlan)
{
    const auto booth = dataDir() / "booth";
    auto bd = boothDigest(booth);
    ASSERT_TRUE(bd) << bd.error().message;
    for (const char* name : {"colorchecker", "metamer", "painting"}) {
        const auto dir = dataDir() / "scenes" / name;
        auto sd = sceneDigest(dir);
        ASSERT_TRUE(sd) << sd.error().message;
        const auto file = dir / renderPlanPath("", name, *sd, *bd, "adaptive_k6").filename();
        ASSERT_TRUE(std::filesystem::exists(file))
                << name << ": no plan " << file << "; the scene or the booth changed since it was "
                << "planned: replica plan --scene scenes/" << name << " --plan-cache "
                << dir.string() << " --force";
        // Found with an empty cache and without planning, every lamp of the booth in it.
        const auto empty = std::filesystem::temp_directory_path() / "replica-no-plans";
        auto plan = loadOrComputeRenderPlan(dir, booth, "adaptive_k6", empty, false);
        ASSERT_TRUE(plan) << plan.error().message;
        EXPECT_EQ(plan->lamps.size(), 3u) << name;
        for (const auto& [lamp, p] : plan->lamps) {
            EXPECT_TRUE(p.met) << name << " " << lamp;
            EXPECT_LE(p.probeP95, kPlanBudget.p95 * kPlanMargin) << name << " " << lamp;
            EXPECT_LE(p.probeMax, kPlanBudget.max * kPlanMargin) << name << " " << lamp;
        }
        // Another basis has no shipped plan: not found, and the message says how to plan.
        auto none = loadOrComputeRenderPlan(dir, booth, "replica_k6", empty, false);
        ASSERT_FALSE(none);
        EXPECT_EQ(none.error().code, ErrorCode::NotFound);
        EXPECT_NE(none.error().message.find("replica plan --scene"), std::string::npos)
                << none.error().message;
    }
}

} // namespace
} // namespace replica::tests
