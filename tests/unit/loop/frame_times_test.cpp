// Frame-time statistics: mean, maximum and percentiles against the exact ones of the same times
// sorted, in bounded memory.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include <platform/loop/frame_times.h>

#include <gtest/gtest.h>

namespace replica::platform {
namespace {

TEST(FrameTimes, PercentilesLieWithinABinAboveTheExactOnes)
{
    // A fixed pseudo-random spread like a loop's: most frames 14-30 ms, a few 40-90 ms.
    std::vector<double> ms;
    std::uint32_t x = 2463534242u;
    FrameTimes t;
    for (int i = 0; i < 5000; ++i) {
        x ^= x << 13;
        x ^= x >> 17;
        x ^= x << 5;
        const double u = static_cast<double>(x) / 4294967296.0;
        const double v = i % 97 == 0 ? 40.0 + 50.0 * u : 14.0 + 16.0 * u;
        ms.push_back(v);
        t.add(v);
    }
    std::vector<double> sorted = ms;
    std::sort(sorted.begin(), sorted.end());
    EXPECT_EQ(t.count(), 5000u);
    double sum = 0.0;
    for (const double v : ms) {
        sum += v;
    }
    EXPECT_NEAR(t.meanMs(), sum / 5000.0, 1e-9);
    EXPECT_EQ(t.maxMs(), sorted.back());
    for (const double q : {0.01, 0.5, 0.95, 0.99, 1.0}) {
        // The exact q-th frame in time order (rank ceil(q n), 1-based).
        const double exact = sorted[static_cast<std::size_t>(std::ceil(q * 5000.0)) - 1];
        const double got = t.percentileMs(q);
        EXPECT_GE(got, exact) << q;
        EXPECT_LE(got, exact + FrameTimes::kBinMs) << q;
        EXPECT_LE(got, t.maxMs()) << q;
    }
    // Frames of at least 33.25 ms (a whole number of bins): counted exactly.
    const auto over = static_cast<std::uint64_t>(
            std::count_if(ms.begin(), ms.end(), [](double v) { return v >= 33.25; }));
    EXPECT_GT(over, 0u);
    EXPECT_EQ(t.atLeast(33.25), over);
    EXPECT_EQ(t.atLeast(0.0), 5000u);
}

TEST(FrameTimes, EmptyLongAndInvalidTimes)
{
    FrameTimes t;
    EXPECT_EQ(t.meanMs(), 0.0);
    EXPECT_EQ(t.percentileMs(0.95), 0.0);
    t.add(std::numeric_limits<double>::quiet_NaN()); // ignored, as are negative times
    t.add(-1.0);
    t.add(std::numeric_limits<double>::infinity());
    EXPECT_EQ(t.count(), 0u);
    // A frame longer than the top bin: the last bin, the exact maximum.
    t.add(2500.0);
    t.add(10.0);
    EXPECT_EQ(t.count(), 2u);
    EXPECT_EQ(t.maxMs(), 2500.0);
    EXPECT_EQ(t.percentileMs(1.0), 2500.0);
    EXPECT_LE(t.percentileMs(0.5), 10.25);
    EXPECT_GE(t.percentileMs(0.5), 10.0);
    EXPECT_EQ(t.atLeast(100.0), 1u);
    EXPECT_NEAR(t.meanMs(), 1255.0, 1e-9);
}

} // namespace
} // namespace replica::platform
