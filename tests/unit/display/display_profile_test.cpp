// Profile JSON round trip, bad profiles, and the shipped synthetic IPS profile: it loads, says it
// is synthetic, and is exactly what the shipped tool and measurement set produce.
#include <filesystem>
#include <fstream>
#include <limits>

#include <nlohmann/json.hpp>
#include <unistd.h>

#include <pipeline/base/data_dir.h>
#include <pipeline/display/display_profile.h>

#include <gtest/gtest.h>

#include "display_test_support.h"

namespace replica::pipeline::display {
namespace {

TEST(DisplayProfile, RoundTripsThroughJson)
{
    const DisplayModel& m = test::fittedSyntheticIps();
    auto back = profileFromJson(profileToJson(m), "p.json");
    ASSERT_TRUE(back.has_value()) << back.error().message;
    for (const glm::dvec3& c :
         {glm::dvec3(0.0), glm::dvec3(12.5, 200.0, 77.0), glm::dvec3(255.0)}) {
        const glm::dvec3 a = m.forward(c);
        const glm::dvec3 b = back->forward(c);
        for (int k = 0; k < 3; ++k) {
            EXPECT_NEAR(a[k], b[k], 1e-9 * (1.0 + std::abs(a[k])));
        }
    }
    EXPECT_EQ(back->viewing.angleDeg, m.viewing.angleDeg);
    EXPECT_DOUBLE_EQ(back->fit.heldOutMeanDe00, m.fit.heldOutMeanDe00);
    EXPECT_EQ(back->condition, MeasurementCondition::Dark);
    // The gamut edge tolerance travels with the profile; a profile without it has none.
    EXPECT_DOUBLE_EQ(back->gamutEdgeTolerance, m.gamutEdgeTolerance);
    EXPECT_DOUBLE_EQ(back->gamutEdgeFloor, m.gamutEdgeFloor);
    DisplayModel none = m;
    none.gamutEdgeTolerance = 0.0;
    none.gamutEdgeFloor = 0.0;
    const std::string noneText = profileToJson(none);
    EXPECT_EQ(noneText.find("gamut_edge_tolerance"), std::string::npos);
    auto noneBack = profileFromJson(noneText, "n.json");
    ASSERT_TRUE(noneBack.has_value()) << noneBack.error().message;
    EXPECT_EQ(noneBack->gamutEdgeTolerance, 0.0);
    DisplayModel t = m;
    t.gamutEdgeTolerance = 0.0042;
    const std::string text = profileToJson(t);
    EXPECT_NE(text.find("gamut_edge_tolerance"), std::string::npos);
    auto withTolerance = profileFromJson(text, "t.json");
    ASSERT_TRUE(withTolerance.has_value()) << withTolerance.error().message;
    EXPECT_DOUBLE_EQ(withTolerance->gamutEdgeTolerance, 0.0042);
}

// The crosstalk term travels with the profile under its own key; a profile without the key (every
// profile before it) is additive, C = 0, and an additive model writes no key.
TEST(DisplayProfile, CrosstalkRoundTripsAndIsZeroWhenAbsent)
{
    DisplayModel m = test::fittedSyntheticIps();
    m.crosstalk = glm::dmat3(0.0);
    const std::string plain = profileToJson(m);
    EXPECT_EQ(plain.find("\"crosstalk\""), std::string::npos);
    auto plainBack = profileFromJson(plain, "p.json");
    ASSERT_TRUE(plainBack.has_value()) << plainBack.error().message;
    EXPECT_EQ(plainBack->crosstalk, glm::dmat3(0.0));
    DisplayModel c = m;
    c.crosstalk = glm::dmat3(glm::dvec3(-0.004, 0.001, 0.0), glm::dvec3(0.0, -0.002, 0.003),
                             glm::dvec3(0.0005, 0.0, -0.006));
    auto back = profileFromJson(profileToJson(c), "c.json");
    ASSERT_TRUE(back.has_value()) << back.error().message;
    EXPECT_EQ(back->crosstalk, c.crosstalk);
    // White: r = 1 everywhere, so XYZ = black + M (1 + C (1, 1, 1)), the column sums.
    const glm::dvec3 want =
            c.blackXyz + c.matrix * (glm::dvec3(1.0) + glm::dvec3(-0.0035, -0.001, -0.003));
    const glm::dvec3 got = back->forward(glm::dvec3(255.0));
    for (int k = 0; k < 3; ++k) {
        EXPECT_NEAR(got[k], want[k], 1e-9 * want[k]);
    }
    // Beyond the bound the fixed-point inverse needs: refused, naming the row.
    DisplayModel big = m;
    big.crosstalk[0][1] = 0.15;
    big.crosstalk[2][1] = -0.1;
    auto bad = profileFromJson(profileToJson(big), "big.json");
    ASSERT_FALSE(bad.has_value());
    EXPECT_NE(bad.error().message.find("crosstalk row G"), std::string::npos)
            << bad.error().message;
}

TEST(DisplayProfile, BadProfilesAreRejectedWithTheReason)
{
    auto err = [](const std::string& text) {
        auto p = profileFromJson(text, "p.json");
        EXPECT_FALSE(p.has_value());
        return p ? std::string() : p.error().message;
    };
    EXPECT_NE(err("{").find("p.json: "), std::string::npos);
    EXPECT_EQ(err("{\"name\": 1}"),
              "p.json: not a Replica display profile (no \"format\": \"replica-display-profile\")");
    std::string good = profileToJson(test::fittedSyntheticIps());
    auto replaced = [&](const std::string& from, const std::string& to) {
        std::string s = good;
        const auto at = s.find(from);
        EXPECT_NE(at, std::string::npos) << from;
        return s.replace(at, from.size(), to);
    };
    EXPECT_EQ(err(replaced("\"version\": 1", "\"version\": 9")),
              "p.json: profile version 9 (this build reads 1)");
    EXPECT_EQ(err(replaced("\"measured_in\": \"dark\"", "\"measured_in\": \"outdoors\"")),
              "p.json: measured_in 'outdoors' must be 'dark' or 'lit-booth'");
    EXPECT_EQ(err(replaced("\"bit_depth\": 8", "\"bit_depth\": 10")),
              "p.json: display profile 'test-ips': channel R tone curve must run from count 0 "
              "(r = 0) to count 1023 (r = 1)");
    EXPECT_EQ(loadProfile("/nonexistent/p.json").error().message,
              "/nonexistent/p.json: cannot open the display profile");
}

// A primary's XYZ is light: [-1, -1, -1] was accepted and inverted to nonsense.
TEST(DisplayProfile, APrimaryWithNegativeLightIsRefusedNamingItsKey)
{
    auto j = nlohmann::json::parse(profileToJson(test::fittedSyntheticIps()));
    j["primaries_xyz_cd_m2"]["r"] = {-1.0, -1.0, -1.0};
    auto p = profileFromJson(j.dump(), "p.json");
    ASSERT_FALSE(p);
    EXPECT_NE(p.error().message.find("p.json: primaries_xyz_cd_m2.r = [-1, -1, -1]"),
              std::string::npos)
            << p.error().message;
    // A measured primary's noise about zero in X or Z stays accepted.
    auto g = nlohmann::json::parse(profileToJson(test::fittedSyntheticIps()));
    const double y = g["primaries_xyz_cd_m2"]["b"][1].get<double>();
    g["primaries_xyz_cd_m2"]["b"][0] = -0.001 * y;
    EXPECT_TRUE(profileFromJson(g.dump(), "p.json"));
}

// A number that is not finite is written as null, which no reader takes: saveProfile refuses it,
// naming the key, and writes nothing (display fit wrote such a profile from a 1e308 reading).
TEST(DisplayProfile, AProfileWithANonFiniteNumberIsNeverWritten)
{
    DisplayModel m = test::fittedSyntheticIps();
    m.fit.additivityLuminancePercent = std::numeric_limits<double>::quiet_NaN();
    const auto file = std::filesystem::temp_directory_path() /
                      ("replica-nan-profile-" + std::to_string(::getpid()) + ".json");
    std::filesystem::remove(file);
    auto saved = saveProfile(m, file);
    ASSERT_FALSE(saved);
    EXPECT_NE(saved.error().message.find("fit.additivity_luminance_percent is not a finite number"),
              std::string::npos)
            << saved.error().message;
    EXPECT_FALSE(std::filesystem::exists(file));
}

TEST(DisplayProfile, ShippedSyntheticProfileIsReproducible)
{
    const auto dir = dataDir() / "displays";
    auto shipped = loadProfile(dir / "wide-ips-synthetic.json");
    ASSERT_TRUE(shipped.has_value()) << shipped.error().message;
    EXPECT_TRUE(shipped->synthetic);
    EXPECT_NE(shipped->description.find("SYNTHETIC"), std::string::npos);
    EXPECT_EQ(shipped->bitDepth, 8);
    EXPECT_FALSE(shipped->viewing.empty());
    EXPECT_GT(shipped->whiteXyz().y, 850.0);

    // The shipped measurements are what 'replica display synth --seed 1' writes, and the profile
    // is what 'replica display fit' makes of them.
    auto meas = loadMeasurementCsv(dir / "wide-ips-synthetic-measurements.csv");
    ASSERT_TRUE(meas.has_value()) << meas.error().message;
    const auto regenerated = syntheticMeasurements(wideIpsGroundTruth(), MeterNoise{}, 1);
    ASSERT_EQ(meas->rows.size(), regenerated.size());
    for (std::size_t i = 0; i < regenerated.size(); ++i) {
        EXPECT_EQ(meas->rows[i].counts, regenerated[i].counts);
        EXPECT_NEAR(meas->rows[i].xyz.y, regenerated[i].xyz.y, 1e-6);
    }
    FitOptions o;
    o.name = shipped->name;
    o.synthetic = true;
    o.toneMethod = ToneMethod::Interpolate; // the shipped profile predates the robust fit
    auto refit = fitDisplay(*meas, o);
    ASSERT_TRUE(refit.has_value()) << refit.error().message;
    for (const glm::dvec3& c : {glm::dvec3(30.0, 60.0, 90.0), glm::dvec3(255.0)}) {
        EXPECT_NEAR(refit->forward(c).y, shipped->forward(c).y, 1e-6 * shipped->forward(c).y);
    }
}

} // namespace
} // namespace replica::pipeline::display
