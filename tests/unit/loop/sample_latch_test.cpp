// The loop's latest-sample semantics: newest wins, held until replaced, gaps counted, history kept.
#include <hal/sample_latch.h>
#include <hal/samples.h>

#include <gtest/gtest.h>

namespace replica::platform {
namespace {

hal::AccelSample sample(std::uint32_t seq, std::int64_t t)
{
    hal::AccelSample s;
    s.sequence = seq;
    s.timestampNs = t;
    s.gravity = glm::dvec3(0.0, -9.8, static_cast<double>(seq));
    return s;
}

TEST(SampleLatch, EmptyUntilFirstSample)
{
    hal::SampleLatch<hal::AccelSample> latch;
    EXPECT_EQ(latch.latest(), nullptr);
    EXPECT_EQ(latch.push({}), 0u);
    EXPECT_EQ(latch.latest(), nullptr);
}

TEST(SampleLatch, LatestOfABatchWinsAndIsHeld)
{
    hal::SampleLatch<hal::AccelSample> latch;
    latch.push({sample(0, 10), sample(1, 20), sample(2, 30)});
    ASSERT_NE(latch.latest(), nullptr);
    EXPECT_EQ(latch.latest()->sequence, 2u);
    // No new samples this tick: the last one is held.
    latch.push({});
    EXPECT_EQ(latch.latest()->sequence, 2u);
    EXPECT_EQ(latch.latest()->gravity.z, 2.0);
}

TEST(SampleLatch, CountsSequenceGapsAsDrops)
{
    hal::SampleLatch<hal::AccelSample> latch;
    EXPECT_EQ(latch.push({sample(0, 0), sample(1, 1)}), 0u);
    EXPECT_EQ(latch.push({sample(5, 5)}), 3u); // 2, 3, 4 lost
    EXPECT_EQ(latch.push({sample(6, 6), sample(9, 9)}), 2u);
}

TEST(SampleLatch, FindsRetainedSamplesBySequenceOnly)
{
    hal::SampleLatch<hal::AccelSample> latch(4);
    for (std::uint32_t i = 0; i < 10; ++i) {
        latch.push({sample(i, i)});
    }
    ASSERT_NE(latch.find(9), nullptr);
    EXPECT_EQ(latch.find(6)->timestampNs, 6);
    EXPECT_EQ(latch.find(5), nullptr); // beyond the history length
    EXPECT_EQ(latch.find(42), nullptr);
}

} // namespace
} // namespace replica::platform
