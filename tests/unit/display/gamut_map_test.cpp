// Hue-keeping gamut mapping and its counters: chroma, over-peak and negative light (rendering-notes
// hard case 12; rendering-background hard cases 16 and 17).
#include <algorithm>
#include <cmath>
#include <limits>

#include <glm/matrix.hpp>

#include <pipeline/display/display_inverse.h>
#include <pipeline/display/dither.h>

#include <gtest/gtest.h>

#include "display_test_support.h"

namespace replica::pipeline::display {
namespace {

glm::dvec2 xy(const glm::dvec3& v)
{
    const double s = v.x + v.y + v.z;
    return {v.x / s, v.y / s};
}

double cross2(const glm::dvec2& a, const glm::dvec2& b)
{
    return a.x * b.y - a.y * b.x;
}

class GamutMapTest : public ::testing::Test
{
protected:
    void SetUp() override
    {
        auto inv = DisplayInverse::build(test::fittedSyntheticIps());
        ASSERT_TRUE(inv.has_value());
        inv_ = std::make_unique<DisplayInverse>(std::move(*inv));
    }
    const DisplayModel& model() const { return inv_->model(); }
    // XYZ the display emits for linear r (may lie outside the cube).
    glm::dvec3 xyzOfLinear(const glm::dvec3& r) const
    {
        return model().blackXyz + model().matrix * r;
    }
    std::unique_ptr<DisplayInverse> inv_;
};

TEST_F(GamutMapTest, ChromaMappingKeepsLuminanceAndDominantWavelength)
{
    // A saturated orange beyond the red-green edge (negative blue) at mid luminance.
    const glm::dvec3 target = xyzOfLinear({0.9, 0.25, -0.08});
    const auto m = mapToGamut(inv_->geometry(), target, GamutMode::HueKeeping);
    EXPECT_EQ(m.gamutClass, GamutClass::Chroma);
    for (int c = 0; c < 3; ++c) {
        EXPECT_GE(m.r[c], 0.0);
        EXPECT_LE(m.r[c], 1.0);
    }
    EXPECT_NEAR(m.r.z, 0.0, 1e-12); // lands on the gamut face it crossed
    const glm::dvec3 shown = xyzOfLinear(m.r);
    EXPECT_NEAR(shown.y, target.y, 1e-9 * target.y);
    // On the line from the display white through the target's chromaticity, between the two.
    // The neutral is the display's grey of the same luminance: black + s * (white - black).
    const double s = (target.y - model().blackXyz.y) / (model().whiteXyz().y - model().blackXyz.y);
    const glm::dvec2 n = xy(model().blackXyz + s * (model().whiteXyz() - model().blackXyz));
    const glm::dvec2 dirTarget = xy(target) - n;
    const glm::dvec2 dirShown = xy(shown) - n;
    EXPECT_NEAR(cross2(dirTarget, dirShown), 0.0, 1e-9);
    EXPECT_GT(glm::dot(dirTarget, dirShown), 0.0);
    EXPECT_LT(glm::length(dirShown), glm::length(dirTarget));

    // Per-channel clipping of the same colour moves the chromaticity off that line.
    const auto clipped = mapToGamut(inv_->geometry(), target, GamutMode::Clip);
    EXPECT_EQ(clipped.gamutClass, GamutClass::Chroma);
    const glm::dvec2 dirClip = xy(xyzOfLinear(clipped.r)) - n;
    EXPECT_GT(std::abs(cross2(dirTarget, dirClip)), 1e-4);
}

TEST_F(GamutMapTest, TooBrightForItsChromaticityLosesOnlyLuminance)
{
    // Tungsten-white-like: inside the primaries' triangle, but red would need more than full drive.
    const glm::dvec3 target = xyzOfLinear({1.2, 0.9, 0.4});
    ASSERT_LT(target.y, model().whiteXyz().y); // not over peak: a chroma-class colour
    const auto m = mapToGamut(inv_->geometry(), target, GamutMode::HueKeeping);
    EXPECT_EQ(m.gamutClass, GamutClass::Chroma);
    EXPECT_NEAR(m.r.x, 1.0, 1e-12);
    const glm::dvec3 above = xyzOfLinear(m.r) - model().blackXyz;
    const glm::dvec3 targetAbove = target - model().blackXyz;
    EXPECT_NEAR(xy(above).x, xy(targetAbove).x, 1e-12);
    EXPECT_NEAR(xy(above).y, xy(targetAbove).y, 1e-12);
    EXPECT_NEAR(above.y / targetAbove.y, 1.0 / 1.2, 1e-12);
}

TEST_F(GamutMapTest, OverPeakScalesToPeakKeepingChromaticity)
{
    const glm::dvec3 white = model().whiteXyz();
    // A near-neutral far above peak: scaled to peak luminance, then (its red channel above 1 at
    // that luminance) down to full red drive; chromaticity kept throughout.
    const glm::dvec3 target = xyzOfLinear({0.5, 0.4, 0.3}) * 5.0;
    ASSERT_GT(target.y, white.y);
    const auto m = mapToGamut(inv_->geometry(), target, GamutMode::HueKeeping);
    EXPECT_EQ(m.gamutClass, GamutClass::OverPeak);
    const glm::dvec3 shown = xyzOfLinear(m.r);
    EXPECT_LE(shown.y, white.y * (1.0 + 1e-12));
    EXPECT_NEAR(std::max({m.r.x, m.r.y, m.r.z}), 1.0, 1e-12);
    EXPECT_NEAR(xy(shown).x, xy(target).x, 2e-3); // up to the black offset's share
    EXPECT_NEAR(xy(shown).y, xy(target).y, 2e-3);
    // The display's own white far above peak maps to exactly peak white.
    const auto w = mapToGamut(inv_->geometry(), white * 3.0, GamutMode::HueKeeping);
    EXPECT_NEAR(xyzOfLinear(w.r).y, white.y, 1e-6 * white.y);
    // A hot specular at 1e6 cd/m^2 (hard case 9): counts finite and in range.
    const auto hot = inv_->invert(white * 1e6);
    EXPECT_EQ(hot.gamutClass, GamutClass::OverPeak);
    for (int c = 0; c < 3; ++c) {
        EXPECT_GE(hot.counts[c], 0.0);
        EXPECT_LE(hot.counts[c], 255.0);
    }
}

TEST_F(GamutMapTest, NegativeLightIsBlackAndCounted)
{
    // Flare larger than the virtual radiance: the target after subtraction is below display black.
    const glm::dvec3 surface{0.8, 0.9, 0.7};
    const glm::dvec3 flare{1.2, 1.3, 1.1};
    const auto r = inv_->invert(surface - flare);
    EXPECT_EQ(r.gamutClass, GamutClass::BelowBlack);
    EXPECT_EQ(r.counts, glm::dvec3(0.0));
    // Above zero but below the panel's black is not reachable either.
    const auto dim = inv_->invert(model().blackXyz * 0.5);
    EXPECT_EQ(dim.gamutClass, GamutClass::BelowBlack);
    EXPECT_EQ(dim.counts, glm::dvec3(0.0));
    const double nan = std::numeric_limits<double>::quiet_NaN();
    const double inf = std::numeric_limits<double>::infinity();
    for (const glm::dvec3& bad : {glm::dvec3(nan, 1, 1), glm::dvec3(1, inf, 1), glm::dvec3(-inf)}) {
        const auto b = inv_->invert(bad);
        EXPECT_EQ(b.gamutClass, GamutClass::BelowBlack);
        EXPECT_EQ(b.counts, glm::dvec3(0.0));
    }
}

TEST_F(GamutMapTest, CountersGiveTheOutOfGamutFraction)
{
    GamutCounters counters;
    const glm::dvec3 inside = xyzOfLinear({0.3, 0.3, 0.3});
    const glm::dvec3 chroma = xyzOfLinear({1.0, 0.9, -0.1});
    const glm::dvec3 bright = model().whiteXyz() * 2.0;
    const glm::dvec3 dark{-1.0, -1.0, -1.0};
    for (const auto& x : {inside, inside, inside, inside, inside, chroma, bright, dark}) {
        counters.add(inv_->invert(x).gamutClass);
    }
    EXPECT_EQ(counters.pixels, 8u);
    EXPECT_EQ(counters.chroma, 1u);
    EXPECT_EQ(counters.overPeak, 1u);
    EXPECT_EQ(counters.belowBlack, 1u);
    EXPECT_DOUBLE_EQ(counters.outOfGamutFraction(), 3.0 / 8.0);
    EXPECT_DOUBLE_EQ(GamutCounters{}.outOfGamutFraction(), 0.0);
}

TEST_F(GamutMapTest, QuantisedCountsAlwaysInRange)
{
    // Saturated tungsten orange and a highlight over peak (hard case 17) through the whole step.
    const glm::dvec3 white = model().whiteXyz();
    for (const auto& x :
         {xyzOfLinear({1.4, 0.5, -0.2}), white * 3.0, glm::dvec3(-5.0), glm::dvec3(1e9)}) {
        const auto r = inv_->invert(x);
        for (int c = 0; c < 3; ++c) {
            const int q = quantiseCount(r.counts[c], 5, 9, 255.0);
            EXPECT_GE(q, 0);
            EXPECT_LE(q, 255);
        }
        EXPECT_NE(r.gamutClass, GamutClass::InGamut);
    }
}

TEST_F(GamutMapTest, WithinTheEdgeToleranceChannelsAreClampedNotMapped)
{
    // Full blue a hair outside the fitted gamut (red at -0.002): without a tolerance the
    // hue-keeping mapping moves it towards the neutral of its luminance and blue drops by about
    // s / (s + 0.002) of the way (s ~ 0.07, blue's share of white's luminance); with the profile's
    // edge tolerance the channels are clamped (the class stays the strict one).
    const glm::dvec3 target = xyzOfLinear({-0.002, 0.0005, 1.0015});
    GamutGeometry g = inv_->geometry();
    g.edgeTolerance = 0.0;
    const auto mapped = mapToGamut(g, target, GamutMode::HueKeeping);
    EXPECT_EQ(mapped.gamutClass, GamutClass::Chroma);
    EXPECT_LT(mapped.r.z, 0.99);
    g.edgeTolerance = 0.003;
    const auto clamped = mapToGamut(g, target, GamutMode::HueKeeping);
    EXPECT_EQ(clamped.gamutClass, GamutClass::Chroma);
    EXPECT_DOUBLE_EQ(clamped.r.x, 0.0);
    EXPECT_NEAR(clamped.r.y, 0.0005, 1e-9);
    EXPECT_DOUBLE_EQ(clamped.r.z, 1.0);
    // White 0.2 % above peak is within it too: clamped, not scaled.
    const glm::dvec3 white = xyzOfLinear(glm::dvec3(1.002));
    const auto peak = mapToGamut(g, white, GamutMode::HueKeeping);
    EXPECT_EQ(peak.gamutClass, GamutClass::OverPeak);
    EXPECT_EQ(peak.r, glm::dvec3(1.0));
    // Relative to the colour below 0: a dark colour with the same excursion is mapped.
    const glm::dvec3 dark = xyzOfLinear({-0.002, 0.0005, 0.1});
    EXPECT_LT(mapToGamut(g, dark, GamutMode::HueKeeping).r.z, 0.099);
    // Beyond the tolerance the mapping is as before.
    const glm::dvec3 far = xyzOfLinear({-0.01, 0.0, 1.0});
    g.edgeTolerance = 0.003;
    const auto farMapped = mapToGamut(g, far, GamutMode::HueKeeping);
    EXPECT_EQ(farMapped.gamutClass, GamutClass::Chroma);
    EXPECT_NEAR(xyzOfLinear(farMapped.r).y, far.y, 1e-9 * far.y);
    // The inverse takes the tolerance from the model (0 when a profile has none).
    DisplayModel m = model();
    m.gamutEdgeTolerance = 0.0;
    auto none = DisplayInverse::build(m);
    ASSERT_TRUE(none.has_value());
    EXPECT_LT(none->invert(target, GamutMode::HueKeeping).linear.z, 0.99);
    m.gamutEdgeTolerance = 0.003;
    auto inv = DisplayInverse::build(m);
    ASSERT_TRUE(inv.has_value());
    EXPECT_EQ(inv->invert(target, GamutMode::HueKeeping).linear.z, 1.0);
}

} // namespace
} // namespace replica::pipeline::display
