// Median cut, summed-area tables and mip chain: conservation, degenerate images, hot texels.
#include <cmath>
#include <random>

#include <pipeline/booth/median_cut.h>

#include <gtest/gtest.h>

namespace replica::pipeline::booth {
namespace {

LuminanceImage randomImage(int w, int h, unsigned seed)
{
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(0.0, 1000.0);
    LuminanceImage img = LuminanceImage::filled(w, h, 0.0);
    for (double& v : img.cdM2) {
        v = u(rng);
    }
    return img;
}

TEST(LuminanceSat, VarianceEqualsBruteForce)
{
    const LuminanceImage img = randomImage(37, 23, 1);
    const LuminanceSat sat(img, 0.004, 0.005);
    const int x0 = 5, y0 = 3, x1 = 30, y1 = 19;
    double l = 0, lx = 0, ly = 0;
    for (int y = y0; y < y1; ++y) {
        for (int x = x0; x < x1; ++x) {
            l += img.at(x, y);
            lx += img.at(x, y) * x * 0.004;
            ly += img.at(x, y) * y * 0.005;
        }
    }
    const double cx = lx / l, cy = ly / l;
    double var = 0;
    for (int y = y0; y < y1; ++y) {
        for (int x = x0; x < x1; ++x) {
            var += img.at(x, y) * (std::pow(x * 0.004 - cx, 2) + std::pow(y * 0.005 - cy, 2));
        }
    }
    EXPECT_NEAR(sat.region(x0, y0, x1, y1).l, l, 1e-9 * l);
    EXPECT_NEAR(sat.variance(x0, y0, x1, y1), var, 1e-8 * var);
}

TEST(MedianCut, ConservesPowerAndTilesTheImage)
{
    const LuminanceImage img = randomImage(64, 40, 2);
    for (SplitRule rule : {SplitRule::EnergyMedian, SplitRule::VarianceMinimise}) {
        MedianCutOptions o;
        o.count = 32;
        o.rule = rule;
        const auto lights = medianCut(img, o);
        ASSERT_EQ(lights.size(), 32u);
        double power = 0.0;
        long area = 0;
        for (const auto& l : lights) {
            power += l.sumCdM2;
            area += static_cast<long>(l.x1 - l.x0) * (l.y1 - l.y0);
            EXPECT_GE(l.centroidX, l.x0);
            EXPECT_LE(l.centroidX, l.x1);
            EXPECT_GE(l.centroidY, l.y0);
            EXPECT_LE(l.centroidY, l.y1);
        }
        EXPECT_NEAR(power, img.sum(), 1e-9 * img.sum());
        EXPECT_EQ(area, 64 * 40);
    }
}

TEST(MedianCut, IsolatesASingleHotTexelAtItsCentre)
{
    LuminanceImage img = LuminanceImage::filled(64, 32, 0.0);
    img.at(17, 9) = 5000.0;
    MedianCutOptions o;
    o.count = 8;
    const auto lights = medianCut(img, o);
    int lit = 0;
    for (const auto& l : lights) {
        EXPECT_TRUE(std::isfinite(l.centroidX) && std::isfinite(l.centroidY));
        if (l.sumCdM2 > 0.0) {
            ++lit;
            EXPECT_DOUBLE_EQ(l.sumCdM2, 5000.0);
            EXPECT_NEAR(l.centroidX, 17.5, 1e-12);
            EXPECT_NEAR(l.centroidY, 9.5, 1e-12);
        }
    }
    EXPECT_EQ(lit, 1);
}

TEST(MedianCut, AllZeroImageGivesOneZeroPowerLight)
{
    const auto lights = medianCut(LuminanceImage::filled(32, 16, 0.0), MedianCutOptions{});
    ASSERT_EQ(lights.size(), 1u);
    EXPECT_EQ(lights[0].sumCdM2, 0.0);
    EXPECT_DOUBLE_EQ(lights[0].centroidX, 16.0);
    EXPECT_DOUBLE_EQ(lights[0].centroidY, 8.0);
}

TEST(MedianCut, MoreLightsThanNonZeroTexelsStopsAtOnePerTexel)
{
    LuminanceImage img = LuminanceImage::filled(20, 10, 0.0);
    img.at(1, 1) = 10.0;
    img.at(15, 2) = 20.0;
    img.at(7, 8) = 30.0;
    MedianCutOptions o;
    o.count = 16;
    const auto lights = medianCut(img, o);
    int lit = 0;
    double power = 0.0;
    for (const auto& l : lights) {
        if (l.sumCdM2 > 0.0) {
            ++lit;
            power += l.sumCdM2;
        }
    }
    EXPECT_EQ(lit, 3);
    EXPECT_DOUBLE_EQ(power, 60.0);
    o.count = 1;
    const auto one = medianCut(img, o);
    ASSERT_EQ(one.size(), 1u);
    EXPECT_DOUBLE_EQ(one[0].sumCdM2, 60.0);
    EXPECT_NEAR(one[0].centroidX, (10 * 1.5 + 20 * 15.5 + 30 * 7.5) / 60.0, 1e-9);
}

TEST(MedianCut, DegenerateStripStopsGracefully)
{
    const LuminanceImage img = randomImage(1000, 1, 3);
    MedianCutOptions o;
    o.count = 256;
    const auto lights = medianCut(img, o);
    EXPECT_EQ(lights.size(), 256u);
    double power = 0.0;
    for (const auto& l : lights) {
        power += l.sumCdM2;
        EXPECT_EQ(l.y0, 0);
        EXPECT_EQ(l.y1, 1);
    }
    EXPECT_NEAR(power, img.sum(), 1e-9 * img.sum());
    o.count = 5000; // more than texels: one light per texel at most
    EXPECT_EQ(medianCut(img, o).size(), 1000u);
}

TEST(MedianCut, VarianceMinimisationKeepsCompactSourcesWhole)
{
    // Two bare lamps of different power: the first cut must fall between them, not through one.
    LuminanceImage img = LuminanceImage::filled(60, 20, 1.0);
    for (int y = 8; y < 12; ++y) {
        for (int x = 10; x < 14; ++x) {
            img.at(x, y) = 4000.0;
        }
        for (int x = 40; x < 44; ++x) {
            img.at(x, y) = 1000.0;
        }
    }
    MedianCutOptions o;
    o.count = 2;
    const auto lights = medianCut(img, o);
    ASSERT_EQ(lights.size(), 2u);
    for (const auto& l : lights) {
        const bool hasA = l.x0 <= 10 && l.x1 >= 14;
        const bool hasB = l.x0 <= 40 && l.x1 >= 44;
        EXPECT_NE(hasA, hasB);
    }
    // The energy median cuts straight through the brighter lamp.
    o.rule = SplitRule::EnergyMedian;
    const auto mc = medianCut(img, o);
    EXPECT_TRUE(mc[0].x1 > 10 && mc[0].x1 < 14);
}

TEST(MipChain, AveragesExactlyAndConservesPowerForOddSizes)
{
    const LuminanceImage img = randomImage(999, 577, 4);
    const MipChain chain = buildMipChain(img);
    ASSERT_EQ(chain.levels[0].width, 1024);
    ASSERT_EQ(chain.levels[0].height, 1024);
    EXPECT_EQ(chain.levels.back().width, 1);
    EXPECT_EQ(chain.levels.back().height, 1);
    const double total = img.sum();
    double scale = 1.0;
    for (const auto& level : chain.levels) {
        EXPECT_NEAR(level.sum() * scale, total, 1e-9 * total);
        scale *= 4.0;
    }
    EXPECT_NEAR(chain.usedU, 999.0 / 1024.0, 1e-15);
    // Level 0 at a texel centre returns the texel; outside the light, zero (dark booth).
    EXPECT_NEAR(chain.sample((100.5) / 999.0, (200.5) / 577.0, 0.0), img.at(100, 200), 1e-9);
    EXPECT_EQ(chain.sample(1.2, 0.5, 0.0), 0.0);
    EXPECT_EQ(chain.sample(-0.01, 0.5, 3.0), 0.0);
    EXPECT_EQ(chain.sample(std::nan(""), 0.5, 0.0), 0.0);
    EXPECT_TRUE(std::isfinite(chain.sample(0.5, 0.5, 1e300)));
    EXPECT_TRUE(std::isfinite(chain.sample(0.5, 0.5, -INFINITY)));
}

TEST(MipChain, NearestLevelFollowsGlsLinearMipmapNearestRule)
{
    // A 64x64 image whose levels are told apart by value: each level's texels hold a constant,
    // so a lookup anywhere names the level it read.
    const MipChain chain = buildMipChain(LuminanceImage::filled(64, 64, 1.0));
    MipChain marked = chain;
    for (std::size_t d = 0; d < marked.levels.size(); ++d) {
        for (auto& t : marked.levels[d].cdM2) {
            t = static_cast<double>(d + 1);
        }
    }
    const auto levelRead = [&](double lod) {
        return marked.sampleNearestLevel(0.5, 0.5, lod) - 1.0;
    };
    // GL: level 0 for lod <= 1/2, then ceil(lod + 1/2) - 1, clamped to the last level.
    EXPECT_EQ(levelRead(-3.0), 0.0);
    EXPECT_EQ(levelRead(0.5), 0.0);
    EXPECT_EQ(levelRead(0.51), 1.0);
    EXPECT_EQ(levelRead(1.5), 1.0);
    EXPECT_EQ(levelRead(1.51), 2.0);
    EXPECT_EQ(levelRead(100.0), static_cast<double>(marked.maxLevel()));
    EXPECT_EQ(levelRead(std::nan("")), 0.0);
    // On a whole level it is the trilinear lookup; outside the light, zero.
    EXPECT_EQ(chain.sampleNearestLevel(0.3, 0.7, 2.0), chain.sample(0.3, 0.7, 2.0));
    EXPECT_EQ(chain.sampleNearestLevel(1.2, 0.5, 0.0), 0.0);
}

TEST(LuminanceCheck, NamesTheFirstBadTexel)
{
    LuminanceImage img = LuminanceImage::filled(8, 4, 1.0);
    EXPECT_TRUE(checkLuminance(img, "light.exr"));
    img.at(3, 2) = std::numeric_limits<double>::infinity();
    auto r = checkLuminance(img, "light.exr");
    ASSERT_FALSE(r);
    EXPECT_NE(r.error().message.find("light.exr: texel (3, 2)"), std::string::npos)
            << r.error().message;
    img.at(3, 2) = -1.0;
    EXPECT_FALSE(checkLuminance(img, "light.exr"));
    // A float's largest value (a damaged or mis-scaled map) is refused, naming the texel; a
    // halogen filament's 2e7 cd/m^2 is not.
    img.at(3, 2) = 3e38;
    r = checkLuminance(img, "light.exr");
    ASSERT_FALSE(r);
    EXPECT_NE(r.error().message.find("light.exr: texel (3, 2)"), std::string::npos);
    EXPECT_NE(r.error().message.find("brighter than the sun"), std::string::npos);
    img.at(3, 2) = 2e7;
    EXPECT_TRUE(checkLuminance(img, "light.exr"));
}

} // namespace
} // namespace replica::pipeline::booth
