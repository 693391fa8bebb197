// The steady cadence's governor: whole divisors of the tick rate from the frames' own times,
// down on a sustained overrun (not on one slow frame), up only with a margin, within the limit.
#include <limits>

#include <platform/loop/cadence.h>

#include <gtest/gtest.h>

namespace replica::platform {
namespace {

constexpr std::int64_t k60Hz = 16'666'667; // ns

// Feeds 'frames' frames of 'ms' each; returns how many of them changed the divisor.
int feed(CadenceGovernor& g, int frames, double ms)
{
    int changes = 0;
    for (int i = 0; i < frames; ++i) {
        changes += g.add(ms) ? 1 : 0;
    }
    return changes;
}

TEST(Cadence, DivisorLimitIsTheWholeStepsDownToTheLowestRate)
{
    EXPECT_EQ(CadenceGovernor::divisorLimit(60.0, 15.0), 4);
    EXPECT_EQ(CadenceGovernor::divisorLimit(60.0, 20.0), 3);
    EXPECT_EQ(CadenceGovernor::divisorLimit(60.0, 25.0), 2); // 2.4: 30 Hz, not 24
    EXPECT_EQ(CadenceGovernor::divisorLimit(30.0, 15.0), 2);
    EXPECT_EQ(CadenceGovernor::divisorLimit(60.0, 60.0), 1); // at the rate: never
    EXPECT_EQ(CadenceGovernor::divisorLimit(10.0, 15.0), 1); // above it: never
    EXPECT_EQ(CadenceGovernor::divisorLimit(240.0, 1.0), CadenceGovernor::kMaxDivisor);
    EXPECT_EQ(CadenceGovernor::divisorLimit(60.0, 0.0), 1);
    EXPECT_EQ(CadenceGovernor::divisorLimit(60.0, std::numeric_limits<double>::quiet_NaN()), 1);
    EXPECT_EQ(CadenceGovernor::divisorLimit(std::numeric_limits<double>::infinity(), 15.0), 1);
}

TEST(Cadence, FramesThatFitThePeriodKeepEveryTick)
{
    CadenceGovernor g(k60Hz, 4);
    EXPECT_EQ(feed(g, 500, 12.0), 0);
    EXPECT_EQ(g.divisor(), 1);
}

TEST(Cadence, FramesOverThePeriodDrawEveryNthTickForTheSmallestNTheyFit)
{
    // The painting on llvmpipe: 28 ms frames at 60 Hz fit 33.3 ms: every 2nd tick.
    CadenceGovernor g(k60Hz, 4);
    // Not before the run's first frames are past (the window is full well before).
    EXPECT_EQ(feed(g, CadenceGovernor::kSettleFrames - 1, 28.0), 0);
    EXPECT_EQ(feed(g, 1, 28.0), 1);
    EXPECT_EQ(g.divisor(), 2);
    EXPECT_DOUBLE_EQ(g.decidedOnMs(), 28.0);
    EXPECT_EQ(feed(g, 500, 28.0), 0); // and stays there: 28 ms does not fit 16.7 with the margin
    EXPECT_EQ(g.divisor(), 2);

    // 40 ms frames go straight to the 3rd tick (50 ms), not one step at a time.
    CadenceGovernor h(k60Hz, 4);
    EXPECT_EQ(feed(h, CadenceGovernor::kSettleFrames, 40.0), 1);
    EXPECT_EQ(h.divisor(), 3);
    // 3 periods are 50 ms: 51 ms frames need the 4th, 49 ms ones do not.
    CadenceGovernor k(k60Hz, 4);
    feed(k, CadenceGovernor::kSettleFrames, 51.0);
    EXPECT_EQ(k.divisor(), 4);
    CadenceGovernor k3(k60Hz, 4);
    feed(k3, CadenceGovernor::kSettleFrames, 49.0);
    EXPECT_EQ(k3.divisor(), 3);
    // Frames of 16 ms at 60 Hz fit (drawn a little late now and then): every tick.
    CadenceGovernor e(k60Hz, 4);
    EXPECT_EQ(feed(e, 300, 16.0), 0);
}

TEST(Cadence, TheRunsFirstFramesWhichCompileDoNotSetTheCadence)
{
    // The painting's start on llvmpipe: frames of 300 ms (the first, compiling), then 33 ms while
    // the lazy passes and caches fill, then the scene's 28 ms: every 2nd tick, not the 3rd
    // those first frames would have asked for.
    CadenceGovernor g(k60Hz, 4);
    feed(g, 3, 300.0);
    feed(g, 12, 33.0);
    feed(g, 100, 28.0);
    EXPECT_EQ(g.divisor(), 2);
}

TEST(Cadence, NeverBelowTheLowestRateAllowed)
{
    CadenceGovernor g(k60Hz, 2);
    feed(g, 200, 140.0); // the glossy cylinder's d65 frames
    EXPECT_EQ(g.divisor(), 2);
    CadenceGovernor off(k60Hz, 1);
    EXPECT_EQ(feed(off, 200, 140.0), 0);
    EXPECT_EQ(off.divisor(), 1);
}

TEST(Cadence, ALampChangesSlowFramesDoNotMoveIt)
{
    // 12 ms frames with a 50 ms lamp change every 120 frames and the frame after it at 30.
    CadenceGovernor g(k60Hz, 4);
    for (int i = 0; i < 1200; ++i) {
        const int r = i % 120;
        g.add(r == 0 ? 50.0 : r == 1 ? 30.0 : 12.0);
        ASSERT_EQ(g.divisor(), 1) << "frame " << i;
    }
}

TEST(Cadence, BackToEveryTickOnlyWhenTheFramesFitWithTheMargin)
{
    CadenceGovernor g(k60Hz, 4);
    feed(g, CadenceGovernor::kSettleFrames, 28.0);
    ASSERT_EQ(g.divisor(), 2);
    // 15 ms frames fit 16.7 but not 0.85 of it (14.2): no swing back.
    EXPECT_EQ(feed(g, 300, 15.0), 0);
    EXPECT_EQ(g.divisor(), 2);
    // 10 ms frames do, once the 95th percentile of the last second's frames (30 at 30 Hz) is
    // one of them: the 29th of 30 in order, so after 29 of them.
    ASSERT_EQ(g.upWindow(), 30);
    EXPECT_EQ(feed(g, 28, 10.0), 0);
    EXPECT_EQ(feed(g, 1, 10.0), 1);
    EXPECT_EQ(g.divisor(), 1);
    EXPECT_DOUBLE_EQ(g.decidedOnMs(), 10.0);
}

TEST(Cadence, UpGoesStraightToTheFastestCadenceTheFramesFit)
{
    CadenceGovernor g(k60Hz, 4);
    feed(g, CadenceGovernor::kSettleFrames, 60.0);
    ASSERT_EQ(g.divisor(), 4);
    // 20 ms frames fit 0.85 x 2 periods (28.3 ms), not 0.85 x 1: the 2nd tick, after a second
    // of them at 15 Hz.
    EXPECT_EQ(g.upWindow(), 15);
    EXPECT_EQ(feed(g, 14, 20.0), 0);
    EXPECT_EQ(feed(g, 1, 20.0), 1);
    EXPECT_EQ(g.divisor(), 2);
}

TEST(Cadence, AFasterLampsPlanIsFollowedWithinASecond)
{
    // The glossy cylinder: 140 ms frames under d65 (the 4th tick), then 25 ms under tungsten.
    CadenceGovernor g(k60Hz, 4);
    feed(g, 60, 140.0);
    ASSERT_EQ(g.divisor(), 4);
    int frames = 0;
    while (g.divisor() == 4 && frames < 100) {
        g.add(25.0);
        ++frames;
    }
    EXPECT_EQ(g.divisor(), 2); // 25 ms fits 0.85 x 33.3
    EXPECT_LE(frames, 15);     // a second at 15 Hz
}

TEST(Cadence, NonFiniteAndNegativeTimesAreIgnored)
{
    CadenceGovernor g(k60Hz, 4);
    for (int i = 0; i < 100; ++i) {
        EXPECT_FALSE(g.add(std::numeric_limits<double>::quiet_NaN()));
        EXPECT_FALSE(g.add(std::numeric_limits<double>::infinity()));
        EXPECT_FALSE(g.add(-5.0));
    }
    EXPECT_EQ(g.divisor(), 1);
    // A zero or negative period is taken as 1 ns, never a division by zero.
    CadenceGovernor z(0, 4);
    feed(z, CadenceGovernor::kSettleFrames, 1.0);
    EXPECT_EQ(z.divisor(), 4);
}

} // namespace
} // namespace replica::platform
