// The fixed ordered dither: every threshold once per tile, local means equal the real value, and
// quantised counts stay in range for any input (hard case 17).
#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include <pipeline/display/dither.h>

#include <gtest/gtest.h>

namespace replica::pipeline::display {
namespace {

TEST(Dither, TileHoldsEachThresholdOnce)
{
    std::vector<float> v(ditherPattern().begin(), ditherPattern().end());
    std::sort(v.begin(), v.end());
    for (std::size_t i = 0; i < v.size(); ++i) {
        EXPECT_FLOAT_EQ(v[i], (static_cast<float>(i) + 0.5f) / 256.0f);
    }
    // Neighbours differ a lot (no low-frequency structure): adjacent thresholds are >= 1/4 apart
    // in the 2x2 sub-pattern.
    const auto& p = ditherPattern();
    EXPECT_GE(std::abs(p[0] - p[1]), 0.25f);
    EXPECT_GE(std::abs(p[0] - p[16]), 0.25f);
}

TEST(Dither, TileMeanEqualsTheRealValue)
{
    for (double v = 10.0; v < 12.0; v += 0.013) {
        double sum = 0.0;
        for (int y = 0; y < kDitherSize; ++y) {
            for (int x = 0; x < kDitherSize; ++x) {
                sum += quantiseCount(v, x, y, 255.0);
            }
        }
        EXPECT_NEAR(sum / 256.0, v, 0.5 / 256.0 + 1e-12) << v;
    }
}

TEST(Dither, GradientHasNoBands)
{
    // A slow 8-bit gradient (one count over 512 pixels): undithered it is a single step of a whole
    // count; dithered, the mean of each 16x16 block follows the ramp to within the ramp's own span
    // across the block (16/512 count) plus the tile's half-threshold step.
    const double tolerance = 16.0 / 512.0 + 0.5 / 256.0;
    double worstUndithered = 0.0;
    for (int bx = 0; bx < 32; ++bx) {
        double sum = 0.0;
        double plain = 0.0;
        double expected = 0.0;
        for (int y = 0; y < 16; ++y) {
            for (int x = bx * 16; x < bx * 16 + 16; ++x) {
                const double v = 100.0 + x / 512.0;
                sum += quantiseCount(v, x, y, 255.0);
                plain += std::floor(v);
                expected += v;
            }
        }
        EXPECT_NEAR(sum / 256.0, expected / 256.0, tolerance) << bx;
        worstUndithered = std::max(worstUndithered, std::abs(plain - expected) / 256.0);
    }
    EXPECT_GT(worstUndithered, 0.9); // what the dither removes: a band of nearly a whole count
}

TEST(Dither, CountsStayInRangeForAnyInput)
{
    const double inf = std::numeric_limits<double>::infinity();
    for (double v : {-5.0, -0.0, 254.9999, 255.0, 300.0, 1e12, inf, -inf, std::nan("")}) {
        const int c = quantiseCount(v, 3, 7, 255.0);
        EXPECT_GE(c, 0);
        EXPECT_LE(c, 255);
    }
    EXPECT_EQ(quantiseCount(std::nan(""), 0, 0, 255.0), 0);
    EXPECT_EQ(quantiseCount(1e12, 0, 0, 255.0), 255);
    EXPECT_EQ(quantiseCount(-3.0, -5, -9, 255.0), 0); // negative pixel coordinates wrap
}

TEST(Dither, ThresholdRepeatsEverySixteenPixelsNegativesIncluded)
{
    // The 2x2 Bayer matrix's order at the tile's corner (index 0, 2, 3, 1 in units of 64, as the
    // recursion's top level puts them): thresholds 0.5/256, 128.5/256, 192.5/256, 64.5/256.
    EXPECT_EQ(ditherThreshold(0, 0), 0.5f / 256.0f);
    EXPECT_EQ(ditherThreshold(1, 1), 64.5f / 256.0f);
    for (int y = -20; y < 20; ++y) {
        for (int x = -20; x < 20; ++x) {
            const int ix = ((x % kDitherSize) + kDitherSize) % kDitherSize;
            const int iy = ((y % kDitherSize) + kDitherSize) % kDitherSize;
            ASSERT_EQ(ditherThreshold(x, y),
                      ditherPattern()[static_cast<std::size_t>(iy * kDitherSize + ix)])
                    << x << "," << y;
        }
    }
}

} // namespace
} // namespace replica::pipeline::display
