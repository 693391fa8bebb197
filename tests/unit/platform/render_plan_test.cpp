// The planner's plan file: what renderPlanJson writes reads back to the same choice, and the
// reader refuses every malformed field with a line naming the file and the field.
#include <string>

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
    p.lamps["tungsten"] = {16, 8, 8, 0.886, 1.981, true};
    p.lamps["d65-fluorescent"] = {32, 4, 8, 0.789, 2.309, true};
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
    std::string noLamps = good.substr(0, good.find("\"lamps\"")) +
                          "\"lamps\": {}, \"scene_digest\": \"0123456789abcdef\"}";
    refused(noLamps, "lamps");
}

} // namespace
} // namespace replica::tests
