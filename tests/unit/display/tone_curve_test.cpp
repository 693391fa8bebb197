// Monotone tone curves: pool-adjacent-violators, shape-preserving interpolation, and the inverse
// over a flat toe (rendering-notes hard case 13).
#include <cmath>

#include <pipeline/display/tone_curve.h>

#include <gtest/gtest.h>

namespace replica::pipeline::display {
namespace {

TEST(PoolAdjacentViolators, AveragesViolatingRuns)
{
    const auto out = poolAdjacentViolators({1.0, 3.0, 2.0, 4.0, 0.0});
    // 3,2 pool to 2.5; then 4,0 pool to 2 and, violating 2.5, pool with it: (3+2+4+0)/4 = 2.25.
    ASSERT_EQ(out.size(), 5u);
    EXPECT_DOUBLE_EQ(out[0], 1.0);
    for (int i = 1; i < 5; ++i) {
        EXPECT_DOUBLE_EQ(out[static_cast<std::size_t>(i)], 2.25);
    }
    const std::vector<double> sorted{0.0, 0.1, 0.1, 0.7};
    EXPECT_EQ(poolAdjacentViolators(sorted), sorted);
}

TEST(ToneCurve, InterpolatesThroughKnotsMonotonically)
{
    std::vector<double> counts;
    std::vector<double> values;
    for (int d = 0; d <= 255; d += 15) {
        counts.push_back(d);
        values.push_back(std::pow(d / 255.0, 2.2));
    }
    ASSERT_EQ(counts.back(), 255.0); // 255 = 17 * 15: full drive is a knot
    const ToneCurve t(counts, values);
    for (std::size_t i = 0; i < counts.size(); ++i) {
        EXPECT_DOUBLE_EQ(t(counts[i]), values[i]);
    }
    double prev = -1.0;
    double maxErr = 0.0;
    for (double d = 0.0; d <= 255.0; d += 0.25) {
        const double v = t(d);
        EXPECT_GE(v, prev);
        prev = v;
        maxErr = std::max(maxErr, std::abs(v - std::pow(d / 255.0, 2.2)));
    }
    EXPECT_LT(maxErr, 2e-3); // a cubic through 15-count knots follows a gamma curve closely
    for (double d : {0.5, 3.0, 40.0, 128.3, 254.9}) {
        EXPECT_NEAR(t.inverse(t(d)), d, 1e-6);
    }
}

TEST(ToneCurve, FlatToeInverseIsFiniteAndPicksTheFirstCount)
{
    // Counts 0..32 give no light at all (a dead toe), then the response rises.
    const ToneCurve t({0, 16, 32, 64, 255}, {0.0, 0.0, 0.0, 0.1, 1.0});
    EXPECT_DOUBLE_EQ(t.inverse(0.0), 0.0);
    const double tiny = t.inverse(1e-9);
    EXPECT_TRUE(std::isfinite(tiny));
    EXPECT_GE(tiny, 32.0);
    EXPECT_LT(tiny, 33.0);
    EXPECT_DOUBLE_EQ(t.inverse(2.0), 255.0);
    EXPECT_DOUBLE_EQ(t.inverse(-1.0), 0.0);
    EXPECT_DOUBLE_EQ(t.inverse(std::nan("")), 0.0);
    EXPECT_DOUBLE_EQ(t(std::nan("")), 0.0);
}

} // namespace
} // namespace replica::pipeline::display
