#include <atomic>
#include <cmath>
#include <numeric>
#include <stdexcept>
#include <vector>

#include <pipeline/base/parallel_for.h>

#include <gtest/gtest.h>

namespace replica::pipeline {
namespace {

TEST(ParallelFor, EveryIndexOnceWhateverTheThreadCount)
{
    for (unsigned threads : {0u, 1u, 2u, 3u, 8u, 100u}) {
        for (std::size_t count : {0u, 1u, 2u, 7u, 45u, 1000u}) {
            std::vector<std::atomic<int>> hits(count);
            parallelFor(
                    count, [&](std::size_t i) { ++hits[i]; }, threads);
            for (std::size_t i = 0; i < count; ++i) {
                ASSERT_EQ(hits[i].load(), 1)
                        << "index " << i << " of " << count << ", " << threads << " threads";
            }
        }
    }
}

TEST(ParallelFor, SlotsWrittenByIndexGiveTheSerialResult)
{
    std::vector<double> serial(500), parallel(500);
    const auto f = [](std::size_t i) { return std::sqrt(static_cast<double>(i) * 1.7) / 3.0; };
    for (std::size_t i = 0; i < serial.size(); ++i) {
        serial[i] = f(i);
    }
    parallelFor(
            parallel.size(), [&](std::size_t i) { parallel[i] = f(i); }, 4);
    EXPECT_EQ(serial, parallel);
}

TEST(ParallelFor, AnExceptionReachesTheCallerAfterEveryThreadStopped)
{
    std::atomic<int> done{0};
    EXPECT_THROW(parallelFor(
                         200,
                         [&](std::size_t i) {
                             if (i == 17) {
                                 throw std::runtime_error("item 17");
                             }
                             ++done;
                         },
                         4),
                 std::runtime_error);
    EXPECT_LT(done.load(), 200);
}

} // namespace
} // namespace replica::pipeline
