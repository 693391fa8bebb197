// The state stage's refusals in the log: each device's first refused sample at once, the rest
// counted into one line an interval with why the last, the counts in the loop's statistics, and
// the viewer leaving and returning to the tracker's view said once each way.
#include <mutex>
#include <string>
#include <vector>

#include <state/scene_estimator.h>

#include <platform/logging.h>
#include <platform/loop/frame_loop.h>
#include <platform/loop/refusal_log.h>

#include <gtest/gtest.h>

#include "../support/shipped_light.h"

namespace replica::platform {
namespace {

struct Lines {
    std::mutex mutex;
    std::vector<std::string> lines;
    std::size_t count(const std::string& part)
    {
        std::lock_guard lock(mutex);
        std::size_t n = 0;
        for (const auto& l : lines) {
            n += l.find(part) != std::string::npos ? 1 : 0;
        }
        return n;
    }
};

TEST(RefusalLog, RefusedSamplesAreSaidOnceAnIntervalWithWhyTheLast)
{
    auto estimator = state::SceneEstimator::create(tests::shippedEstimatorSetup());
    ASSERT_TRUE(estimator) << estimator.error().message;
    Lines seen;
    auto tap =
            tapLogs(spdlog::level::info, [&](auto, const std::string& area, const std::string& m) {
                std::lock_guard lock(seen.mutex);
                seen.lines.push_back(area + ": " + m);
            });
    RefusalLog log;
    LoopStats stats;
    pipeline::scene::SceneState st;
    hal::AccelSample a;
    hal::PoseSample p;
    p.tracked = true;
    p.eyeTrackerM = {0.0, 0.05, 0.5};
    constexpr std::int64_t kFrameNs = 100'000'000; // 10 Hz: 100 frames in 10 s
    for (int i = 0; i < 250; ++i) {
        const std::int64_t t = i * kFrameNs;
        a.sequence = static_cast<std::uint32_t>(i + 1);
        // Every reading 0.8 g: the sensor's scale is off, no tilt is ever taken.
        a.gravity = glm::dvec3{0.0, -0.8 * 9.80665, 0.0};
        p.sequence = static_cast<std::uint32_t>(i + 1);
        p.timestampNs = t;
        p.tracked = i < 120 || i > 150; // the viewer away for 3 s
        p.eyeTrackerM.x = i == 60 ? 1e300 : 0.001 * i;
        estimator->update(st, nullptr, &p, &a);
        log.after(*estimator, t, stats);
    }
    // 250 readings refused: said at once, then every 10 s (t = 10, 20 s: 100 each), the last 49
    // still pending (the run's summary counts them).
    EXPECT_EQ(seen.count("state: accel: 1 tilt reading not used (the last: |g| 7.845 m/s^2 "
                         "(0.80 g), outside 0.9-1.1 g"),
              1u);
    EXPECT_EQ(seen.count("state: accel: 100 tilt readings not used"), 2u);
    EXPECT_EQ(stats.refused["accel"], 250u);
    EXPECT_EQ(seen.count("state: tracker: 1 pose not used (the last: an eye 1e+300 m"), 1u);
    EXPECT_EQ(stats.refused["tracker"], 1u);
    EXPECT_EQ(seen.count("the viewer is out of view; the frame keeps the eye at (0.119, 0.470, "
                         "0.550) m"),
              1u);
    EXPECT_EQ(seen.count("the viewer is in view again after 3.1 s"), 1u);
    EXPECT_EQ(stats.refused.count("spectrometer"), 0u);
}

} // namespace
} // namespace replica::platform
