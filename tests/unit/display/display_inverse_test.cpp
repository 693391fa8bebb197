// forward(inverse(x)) = x within dE00 0.05 across the gamut, near black and at peak white, for
// the exact and the LUT tone inverse; the 3-D LUT variant stays finite and close.
#include <cmath>

#include <pipeline/display/display_inverse.h>
#include <pipeline/display/xyz_difference.h>

#include <gtest/gtest.h>

#include "display_test_support.h"

namespace replica::pipeline::display {
namespace {

std::vector<glm::dvec3> inGamutCounts()
{
    std::vector<glm::dvec3> out;
    for (double r = 0.0; r <= 255.0; r += 17.0) {
        for (double g = 0.0; g <= 255.0; g += 17.0) {
            for (double b = 0.0; b <= 255.0; b += 17.0) {
                out.emplace_back(r, g, b);
            }
        }
    }
    // Near black: fractions of a count on one channel and on all three, and peak white.
    for (double v : {0.05, 0.25, 0.5, 1.0, 1.5, 2.0, 3.0, 5.0}) {
        out.emplace_back(v, 0.0, 0.0);
        out.emplace_back(0.0, v, 0.0);
        out.emplace_back(0.0, 0.0, v);
        out.emplace_back(v, v, v);
    }
    out.emplace_back(255.0, 255.0, 255.0);
    out.emplace_back(254.5, 255.0, 255.0);
    return out;
}

TEST(DisplayInverse, ForwardOfInverseIsIdentityInGamut)
{
    const DisplayModel& model = test::fittedSyntheticIps();
    auto inv = DisplayInverse::build(model);
    ASSERT_TRUE(inv.has_value()) << inv.error().message;
    const glm::dvec3 white = model.whiteXyz();
    for (ToneInverse tone : {ToneInverse::Exact, ToneInverse::Lut}) {
        double worst = 0.0;
        for (const auto& c : inGamutCounts()) {
            const glm::dvec3 xyz = model.forward(c);
            const InverseResult r = inv->invert(xyz, GamutMode::HueKeeping, tone);
            EXPECT_TRUE(r.inGamut()) << c.x << "," << c.y << "," << c.z;
            const double de = deltaE2000Xyz(model.forward(r.counts), xyz, white);
            worst = std::max(worst, de);
            EXPECT_LT(de, 0.05) << (tone == ToneInverse::Lut ? "lut " : "exact ") << c.x << ","
                                << c.y << "," << c.z;
        }
        if (tone == ToneInverse::Exact) {
            EXPECT_LT(worst, 1e-6); // bisection to 1e-12 counts: exact up to rounding
        }
    }
    // Peak white maps to full drive; black to zero.
    const auto w = inv->invert(white, GamutMode::HueKeeping, ToneInverse::Exact);
    EXPECT_NEAR(w.counts.x, 255.0, 1e-6);
    EXPECT_NEAR(w.counts.y, 255.0, 1e-6);
    EXPECT_NEAR(w.counts.z, 255.0, 1e-6);
    const auto k = inv->invert(model.blackXyz, GamutMode::HueKeeping, ToneInverse::Exact);
    EXPECT_TRUE(k.inGamut());
    EXPECT_NEAR(k.counts.x + k.counts.y + k.counts.z, 0.0, 1e-6);
}

// With crosstalk the inverse undoes it: counts -> the model's forward -> counts again, for colours
// inside the gamut (each channel driven enough that y = r + C p(r) stays in [0, 1]), at a
// crosstalk twenty times a real panel's and of mixed sign.
TEST(DisplayInverse, InvertsTheCrosstalkTerm)
{
    DisplayModel m = test::fittedSyntheticIps();
    m.crosstalk = glm::dmat3(glm::dvec3(-0.05, 0.02, -0.03), glm::dvec3(-0.04, -0.06, 0.01),
                             glm::dvec3(0.03, -0.05, -0.07));
    m.gamutEdgeTolerance = 0.0;
    auto inv = DisplayInverse::build(m);
    ASSERT_TRUE(inv.has_value()) << inv.error().message;
    auto additive = m;
    additive.crosstalk = glm::dmat3(0.0);
    auto invAdd = DisplayInverse::build(additive);
    ASSERT_TRUE(invAdd.has_value());
    double worst = 0.0;
    double moved = 0.0;
    for (double r : {110.0, 180.0, 250.0}) {
        for (double g : {100.0, 170.0, 230.0}) {
            for (double b : {120.0, 180.0, 240.0}) {
                const glm::dvec3 counts(r, g, b);
                const glm::dvec3 xyz = m.forward(counts);
                const auto out = inv->invert(xyz, GamutMode::Clip, ToneInverse::Exact);
                worst = std::max(worst, glm::length(out.counts - counts));
                moved = std::max(
                        moved,
                        glm::length(
                                invAdd->invert(xyz, GamutMode::Clip, ToneInverse::Exact).counts -
                                counts));
            }
        }
    }
    EXPECT_LT(worst, 1e-3);
    EXPECT_GT(moved, 3.0) << "the additive inverse gets these right: the test cannot tell";
}

TEST(DisplayInverse, ThreeDimensionalLutIsFiniteAndClose)
{
    const DisplayModel& model = test::fittedSyntheticIps();
    auto inv = DisplayInverse::build(model);
    ASSERT_TRUE(inv.has_value());
    const DisplayLut3d lut = DisplayLut3d::build(*inv, 33);
    const glm::dvec3 white = model.whiteXyz();
    double sum = 0.0;
    int n = 0;
    for (const auto& c : inGamutCounts()) {
        const glm::dvec3 xyz = model.forward(c);
        const glm::dvec3 counts = lut.counts(xyz);
        ASSERT_TRUE(std::isfinite(counts.x) && std::isfinite(counts.y) && std::isfinite(counts.z));
        sum += deltaE2000Xyz(model.forward(glm::clamp(counts, 0.0, 255.0)), xyz, white);
        ++n;
    }
    // Looser than the analytic path (that is the point of measuring it), but a working LUT.
    EXPECT_LT(sum / n, 1.0);
    // Lattice nodes themselves are exact.
    const glm::dvec3 nodeXyz = white * 0.125; // u = 0.5 on every axis
    const glm::dvec3 exact = inv->invert(nodeXyz, GamutMode::HueKeeping, ToneInverse::Exact).counts;
    const glm::dvec3 fromLut = lut.counts(nodeXyz);
    EXPECT_NEAR(fromLut.x, exact.x, 1e-9);
    EXPECT_NEAR(fromLut.y, exact.y, 1e-9);
    EXPECT_NEAR(fromLut.z, exact.z, 1e-9);
}

TEST(DisplayInverse, RejectsAnInvalidModel)
{
    DisplayModel bad = test::fittedSyntheticIps();
    bad.matrix = glm::dmat3(0.0);
    auto inv = DisplayInverse::build(bad);
    ASSERT_FALSE(inv.has_value());
    EXPECT_EQ(inv.error().message, "display profile 'test-ips': the primaries matrix is singular");
}

} // namespace
} // namespace replica::pipeline::display
