// The fit recovers a known synthetic display to within its measurement noise, and every
// degenerate measurement set fails with a message that says what is wrong.
#include <cmath>
#include <random>

#include <pipeline/display/xyz_difference.h>
#include <pipeline/offline/display/display_fit.h>
#include <pipeline/offline/display/synthetic_display.h>

#include <gtest/gtest.h>

namespace replica::pipeline::display {
namespace {

MeasurementSet setFrom(std::vector<Measurement> rows)
{
    MeasurementSet s;
    s.source = "meas.csv";
    s.bitDepth = 8;
    for (std::size_t i = 0; i < rows.size(); ++i) {
        rows[i].line = static_cast<int>(i) + 2;
    }
    s.rows = std::move(rows);
    return s;
}

std::string fitError(const std::vector<Measurement>& rows)
{
    auto m = fitDisplay(setFrom(rows), FitOptions{});
    EXPECT_FALSE(m.has_value());
    return m ? std::string() : m.error().message;
}

bool isRampOf(const Measurement& m, int c)
{
    for (int k = 0; k < 3; ++k) {
        if ((k == c) != (m.counts[k] > 0.0)) {
            return false;
        }
    }
    return true;
}

TEST(DisplayFit, RecoversAKnownDisplayWithinMeasurementNoise)
{
    SyntheticDisplay truth = wideIpsGroundTruth();
    truth.interaction = 0.0; // the model has no crosstalk term; test recovery on a display without
    const MeterNoise noise;
    const auto rows = syntheticMeasurements(truth, noise, 7);
    auto model = fitDisplay(setFrom(rows), FitOptions{});
    ASSERT_TRUE(model.has_value()) << model.error().message;

    // The noise level itself, in the same units: each reading against the truth.
    const glm::dvec3 white = truth.forward(glm::dvec3(255.0));
    double noiseDe = 0.0;
    for (const auto& m : rows) {
        noiseDe += deltaE2000Xyz(m.xyz, truth.forward(m.counts), white);
    }
    noiseDe /= static_cast<double>(rows.size());

    // The fitted model against the truth on fresh colours, none of them measured.
    std::mt19937_64 rng(99);
    double fitDe = 0.0;
    double fitMax = 0.0;
    const int n = 400;
    for (int i = 0; i < n; ++i) {
        glm::dvec3 c;
        for (int k = 0; k < 3; ++k) {
            c[k] = static_cast<double>(rng() % 25600) / 100.0;
        }
        const double de = deltaE2000Xyz(model->forward(c), truth.forward(c), white);
        fitDe += de;
        fitMax = std::max(fitMax, de);
    }
    fitDe /= n;
    EXPECT_LT(fitDe, noiseDe) << "model error should sit below a single reading's noise";
    EXPECT_LT(fitMax, 4.0 * noiseDe);
    // The held-out report is of the order of the noise (held-out colours carry noise themselves).
    EXPECT_GT(model->fit.heldOutColours, 50);
    EXPECT_LT(model->fit.heldOutMeanDe00, 2.0 * noiseDe);
    // Peak white and black recovered within the meter's noise (0.2 % + 0.005 cd/m^2, averaged).
    EXPECT_NEAR(model->whiteXyz().y, white.y, 0.004 * white.y);
    EXPECT_NEAR(model->blackXyz.y, truth.blackXyz.y, 0.01);
    // No channel interaction in this display: the additivity check sees only noise.
    EXPECT_LT(std::abs(model->fit.additivityLuminancePercent), 0.5);
}

TEST(DisplayFit, AdditivityCheckSeesChannelInteraction)
{
    SyntheticDisplay truth = wideIpsGroundTruth();
    truth.interaction = 0.02; // white 2 % darker than R+G+B
    auto model = fitDisplay(setFrom(syntheticMeasurements(truth, MeterNoise{}, 3)), FitOptions{});
    ASSERT_TRUE(model.has_value()) << model.error().message;
    EXPECT_NEAR(model->fit.additivityLuminancePercent, -2.0, 0.3);
}

TEST(DisplayFit, ToleratesSmallWigglesNearBlack)
{
    auto rows = syntheticMeasurements(wideIpsGroundTruth(), MeterNoise{}, 5);
    // A meter reading near black a little low: pooled, not rejected.
    for (auto& m : rows) {
        if (isRampOf(m, 0) && m.counts.x == 16.0) {
            m.xyz *= 0.9;
        }
    }
    auto model = fitDisplay(setFrom(rows), FitOptions{});
    ASSERT_TRUE(model.has_value()) << model.error().message;
}

TEST(DisplayFit, DegenerateSetsFailWithClearMessages)
{
    const auto good = syntheticMeasurements(wideIpsGroundTruth(), MeterNoise{}, 11);

    {
        std::vector<Measurement> rows;
        for (const auto& m : good) {
            if (m.counts != glm::dvec3(0.0)) {
                rows.push_back(m);
            }
        }
        EXPECT_NE(fitError(rows).find("no black (0,0,0) measurement"), std::string::npos);
    }
    {
        // Missing ramp: the green ramp is not measured.
        std::vector<Measurement> rows;
        for (const auto& m : good) {
            if (!isRampOf(m, 1)) {
                rows.push_back(m);
            }
        }
        const auto msg = fitError(rows);
        EXPECT_NE(msg.find("missing ramp: channel G has 0 non-zero levels"), std::string::npos)
                << msg;
    }
    {
        // A ramp without its full-drive point.
        std::vector<Measurement> rows;
        for (const auto& m : good) {
            if (!(isRampOf(m, 2) && m.counts.z == 255.0)) {
                rows.push_back(m);
            }
        }
        const auto msg = fitError(rows);
        EXPECT_NE(msg.find("channel B has"), std::string::npos) << msg;
        EXPECT_NE(msg.find("no full-drive point"), std::string::npos) << msg;
    }
    {
        // Dead channel: blue emits nothing above black.
        auto rows = good;
        const glm::dvec3 black = wideIpsGroundTruth().blackXyz;
        for (auto& m : rows) {
            if (isRampOf(m, 2)) {
                m.xyz = black;
            }
        }
        const auto msg = fitError(rows);
        EXPECT_NE(msg.find("channel B is dead"), std::string::npos) << msg;
        EXPECT_NE(msg.find("meas.csv:"), std::string::npos) << msg;
    }
    {
        // Singular matrix: the green ramp carries red's light (mislabelled ramps).
        auto rows = good;
        const SyntheticDisplay d = wideIpsGroundTruth();
        for (auto& m : rows) {
            if (isRampOf(m, 1)) {
                m.xyz = d.forward(glm::dvec3(m.counts.y, 0.0, 0.0));
            }
        }
        const auto msg = fitError(rows);
        EXPECT_NE(msg.find("primaries matrix is singular"), std::string::npos) << msg;
        EXPECT_NE(msg.find("channels R and G"), std::string::npos) << msg;
    }
    {
        // Non-monotonic: the red ramp drops by a third half way up.
        auto rows = good;
        for (auto& m : rows) {
            if (isRampOf(m, 0) && m.counts.x >= 160.0 && m.counts.x <= 200.0) {
                m.xyz = wideIpsGroundTruth().forward(glm::dvec3(m.counts.x - 100.0, 0.0, 0.0));
            }
        }
        const auto msg = fitError(rows);
        EXPECT_NE(msg.find("channel R response is not monotonic"), std::string::npos) << msg;
        EXPECT_NE(msg.find("at count 160"), std::string::npos) << msg;
    }
    {
        // Too few colours off the ramps for a held-out check.
        std::vector<Measurement> rows;
        int colours = 0;
        for (const auto& m : good) {
            const int nonZero = (m.counts.x > 0) + (m.counts.y > 0) + (m.counts.z > 0);
            if (nonZero > 1 && ++colours > 3) {
                continue;
            }
            rows.push_back(m);
        }
        const auto msg = fitError(rows);
        EXPECT_NE(msg.find("only 3 measured colours off the single-channel ramps"),
                  std::string::npos)
                << msg;
    }
}

// An ordinary ArgyllCMS set (targen -d3 -f200) has four levels per ramp: the robust fit takes
// them with the GOG curve alone and says so; two levels (targen -d3 -f64) are refused, naming the
// targen option that adds ramp steps.
TEST(DisplayFit, ShortRampsFitGogAloneAndSaySo)
{
    SyntheticDisplay truth = wideIpsGroundTruth();
    truth.interaction = 0.0;
    SessionPlan plan;
    plan.rampStep = 64; // 64, 128, 192 and full drive
    plan.fullDriveRepeats = 1;
    plan.randomColours = 150;
    const auto rows = syntheticSession(truth, MeterNoise{}, plan, 3);
    auto model = fitDisplay(setFrom(rows), FitOptions{});
    ASSERT_TRUE(model.has_value()) << model.error().message;
    EXPECT_TRUE(model->fit.gogOnlyForShortRamps);
    for (int c = 0; c < 3; ++c) {
        EXPECT_EQ(model->fit.rampLevels[static_cast<std::size_t>(c)], 4) << c;
        EXPECT_EQ(model->fit.toneShape[static_cast<std::size_t>(c)], "gog") << c;
    }
    // The S-shaped panel through a GOG curve from four levels, against the panel on colours
    // never measured: ΔE00 mean 0.62, max 2.70 (seed 3; the S-shoulder GOG cannot follow); bounds
    // 1.6 and 1.5 times that.
    const glm::dvec3 white = truth.forward(glm::dvec3(255.0));
    std::mt19937_64 rng(99);
    double sum = 0.0;
    double worst = 0.0;
    for (int i = 0; i < 400; ++i) {
        const glm::dvec3 d(static_cast<double>(rng() % 256), static_cast<double>(rng() % 256),
                           static_cast<double>(rng() % 256));
        const double de = deltaE2000Xyz(model->forward(d), truth.forward(d), white);
        sum += de;
        worst = std::max(worst, de);
    }
    RecordProperty("short_ramps_truth_mean_de00", std::to_string(sum / 400.0));
    RecordProperty("short_ramps_truth_max_de00", std::to_string(worst));
    EXPECT_LT(sum / 400.0, 1.0);
    EXPECT_LT(worst, 4.0);
    // The cross-validated fit of the dense plan does not take the short-ramp path.
    auto dense = fitDisplay(setFrom(syntheticMeasurements(truth, MeterNoise{}, 3)), FitOptions{});
    ASSERT_TRUE(dense.has_value());
    EXPECT_FALSE(dense->fit.gogOnlyForShortRamps);

    plan.rampStep = 128; // 128 and full drive: two levels
    const auto msg = fitError(syntheticSession(truth, MeterNoise{}, plan, 3));
    EXPECT_NE(msg.find("missing ramp: channel R has 2 non-zero levels"), std::string::npos) << msg;
    EXPECT_NE(msg.find("targen -d3 -s 9"), std::string::npos) << msg;
}

TEST(MeasurementCsv, ParsesAndRejectsBadInputNamingTheLine)
{
    const std::string ok = "# comment\nR,G,B,X,Y,Z\n0,0,0,0.5,0.6,0.8\n255,255,255,850,900,980\n";
    auto set = parseMeasurementCsv(ok, "m.csv");
    ASSERT_TRUE(set.has_value()) << set.error().message;
    EXPECT_EQ(set->bitDepth, 8);
    ASSERT_EQ(set->rows.size(), 2u);
    EXPECT_EQ(set->rows[1].line, 4);
    EXPECT_DOUBLE_EQ(set->rows[1].xyz.y, 900.0);

    auto err = [](const std::string& text, int bits = 0) {
        auto s = parseMeasurementCsv(text, "m.csv", bits);
        EXPECT_FALSE(s.has_value());
        return s ? std::string() : s.error().message;
    };
    EXPECT_EQ(err(""), "m.csv: no header line R,G,B,X,Y,Z (empty file?)");
    EXPECT_NE(err("R,G,B,X,Y\n").find("m.csv:1: header must be R,G,B,X,Y,Z"), std::string::npos);
    EXPECT_EQ(err("R,G,B,X,Y,Z\n"), "m.csv: no measurements");
    EXPECT_EQ(err("R,G,B,X,Y,Z\n0,0,0,1,1\n"), "m.csv:2: expected 6 values, found 5");
    EXPECT_EQ(err("R,G,B,X,Y,Z\n0,0,0,1,abc,1\n"),
              "m.csv:2: 'abc' in column Y is not a finite number");
    EXPECT_EQ(err("R,G,B,X,Y,Z\n0,0,nan,1,1,1\n"),
              "m.csv:2: 'nan' in column B is not a finite number");
    EXPECT_EQ(err("R,G,B,X,Y,Z\n0,1.5,0,1,1,1\n"),
              "m.csv:2: count 1.5 in column G must be a non-negative integer");
    EXPECT_EQ(err("R,G,B,X,Y,Z\n0,0,0,1,-2,1\n255,0,0,1,1,1\n"),
              "m.csv:2: negative luminance Y = -2 cd/m^2");
    EXPECT_NE(err("R,G,B,X,Y,Z\n0,0,0,1,1,1\n200,0,0,1,1,1\n")
                      .find("the largest count is 200, not 2^n - 1"),
              std::string::npos);
    EXPECT_EQ(err("R,G,B,X,Y,Z\n0,0,0,1,1,1\n1023,0,0,1,1,1\n", 8),
              "m.csv:3: count above 255 (the 8-bit maximum)");
    EXPECT_EQ(loadMeasurementCsv("/nonexistent/m.csv").error().message,
              "/nonexistent/m.csv: cannot open the measurement file");
}

TEST(MeasurementCsv, RoundTripsTheSyntheticSet)
{
    const auto rows = syntheticMeasurements(wideIpsGroundTruth(), MeterNoise{}, 1);
    auto set = parseMeasurementCsv(measurementCsv(rows, "synthetic\ntwo lines"), "s.csv");
    ASSERT_TRUE(set.has_value()) << set.error().message;
    ASSERT_EQ(set->rows.size(), rows.size());
    for (std::size_t i = 0; i < rows.size(); ++i) {
        EXPECT_EQ(set->rows[i].counts, rows[i].counts);
        EXPECT_NEAR(set->rows[i].xyz.y, rows[i].xyz.y, 1e-6);
    }
}

} // namespace
} // namespace replica::pipeline::display
