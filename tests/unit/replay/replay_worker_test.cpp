// Replay's checks off the frame thread (FrameWorker): frames reach them in order, their buffers
// moved, not copied; and the shown-frame check on a thumbnail that matches byte for byte.
#include <atomic>
#include <chrono>
#include <cstdint>
#include <stdexcept>
#include <thread>
#include <vector>

#include <platform/cli/replay_shown.h>
#include <platform/cli/replay_worker.h>
#include <platform/image/thumbnail.h>

#include <gtest/gtest.h>

#include "../display/display_test_support.h"

namespace replica::platform {
namespace {

pipeline::render::RenderedFrame frameOf(int width, int height, std::uint8_t seed)
{
    pipeline::render::RenderedFrame f;
    f.width = width;
    f.height = height;
    const auto pixels = static_cast<std::size_t>(width) * static_cast<std::size_t>(height);
    f.xyz.assign(pixels * 4, static_cast<float>(seed));
    f.rgba.resize(pixels * 4);
    for (std::size_t i = 0; i < f.rgba.size(); ++i) {
        f.rgba[i] = static_cast<std::uint8_t>((i * 31 + std::size_t{seed} * 7) & 0xff);
    }
    return f;
}

TEST(FrameWorker, ChecksEveryFrameInOrderWithItsOwnBuffers)
{
    struct Seen {
        std::uint64_t frame;
        float xyz0;
        std::uint8_t rgba0;
        const float* data;
    };
    std::vector<Seen> seen; // written by the worker only, read after finish()
    std::vector<const float*> pushed;
    {
        FrameWorker worker(
                [&](const recordings::FrameRecord& f, const pipeline::render::RenderedFrame& im) {
                    // Slower than the pushes: the queue fills and push() waits.
                    std::this_thread::sleep_for(std::chrono::milliseconds(2));
                    seen.push_back({f.frameIndex, im.xyz[0], im.rgba[0], im.xyz.data()});
                },
                2);
        pipeline::render::RenderedFrame image;
        for (std::uint64_t k = 0; k < 12; ++k) {
            const auto fresh = frameOf(16, 8, static_cast<std::uint8_t>(k));
            // The renderer's read-back: into the buffers the loop holds, resized only if needed.
            image.width = fresh.width;
            image.height = fresh.height;
            image.xyz.resize(fresh.xyz.size());
            image.rgba.resize(fresh.rgba.size());
            std::copy(fresh.xyz.begin(), fresh.xyz.end(), image.xyz.begin());
            std::copy(fresh.rgba.begin(), fresh.rgba.end(), image.rgba.begin());
            pushed.push_back(image.xyz.data());
            worker.push(recordings::FrameRecord{k, static_cast<std::int64_t>(k) * 1000, {}}, image);
            if (k >= 4) {
                // Once frames have come back from the worker, the loop gets buffers of the
                // frame's size: the next read-back allocates nothing.
                EXPECT_EQ(image.xyz.size(), fresh.xyz.size()) << k;
                EXPECT_EQ(image.rgba.size(), fresh.rgba.size()) << k;
            }
        }
        worker.finish();
        ASSERT_EQ(seen.size(), 12u);
        // 12 checks of 2 ms behind a queue of 2: the pushes waited for most of them.
        EXPECT_GT(worker.waitedS(), 0.01);
    }
    for (std::uint64_t k = 0; k < seen.size(); ++k) {
        EXPECT_EQ(seen[k].frame, k);
        EXPECT_EQ(seen[k].xyz0, static_cast<float>(k));
        EXPECT_EQ(seen[k].rgba0, frameOf(16, 8, static_cast<std::uint8_t>(k)).rgba[0]);
        // The worker saw the very buffer the frame was read back into: moved, not copied.
        EXPECT_EQ(seen[k].data, pushed[k]) << k;
    }
}

TEST(FrameWorker, DestructionChecksWhatIsLeft)
{
    std::atomic<int> checked{0};
    {
        FrameWorker worker([&](const auto&, const auto&) { ++checked; }, 3);
        auto image = frameOf(4, 4, 1);
        for (std::uint64_t k = 0; k < 5; ++k) {
            worker.push(recordings::FrameRecord{k, 0, {}}, image);
        }
    }
    EXPECT_EQ(checked.load(), 5);
}

TEST(FrameWorker, ACheckThatThrowsStopsTheChecksAndFinishThrowsIt)
{
    std::vector<std::uint64_t> checked;
    FrameWorker worker(
            [&](const recordings::FrameRecord& f, const auto&) {
                if (f.frameIndex == 2) {
                    throw std::runtime_error("frame 2");
                }
                checked.push_back(f.frameIndex);
            },
            2);
    auto image = frameOf(4, 4, 1);
    for (std::uint64_t k = 0; k < 6; ++k) {
        worker.push(recordings::FrameRecord{k, 0, {}}, image);
    }
    EXPECT_THROW(worker.finish(), std::runtime_error);
    EXPECT_EQ(checked, (std::vector<std::uint64_t>{0, 1}));
    EXPECT_NO_THROW(worker.finish()); // thrown once
}

// A bit-exact replay's thumbnail is the replayed frame's downscale byte for byte: every pixel's
// ΔE00 is 0 (the fast path), and one changed count is measured as a difference.
TEST(ShownComparison, AThumbnailOfTheSameBytesIsZeroAndAChangedOneIsNot)
{
    const auto& model = pipeline::display::test::fittedSyntheticIps();
    auto frame = frameOf(64, 40, 3);
    recordings::Recording rec;
    auto png = encodePngRgb(downscaleRgba(64, 40, frame.rgba, 32));
    ASSERT_TRUE(png) << png.error().message;
    rec.thumbnails.push_back({5000, 5, *png});
    ShownComparison same(rec, model, 2.0);
    ASSERT_TRUE(same.add(5, 5000, 64, 40, frame.rgba));
    ASSERT_TRUE(same.add(6, 6000, 64, 40, frame.rgba)); // no thumbnail at that tick
    ASSERT_EQ(same.measured().size(), 1u);
    const auto& s = same.measured()[0].stats;
    EXPECT_EQ(s.pixels, 32u * 20u);
    EXPECT_EQ(s.mean, 0.0);
    EXPECT_EQ(s.p95, 0.0);
    EXPECT_EQ(s.max, 0.0);
    EXPECT_EQ(s.fractionAbove1, 0.0);
    EXPECT_TRUE(same.within());

    // Every source pixel of thumbnail pixel (0, 0) (the top-left: the frame's top rows are its
    // last, GL order) much darker in red: that thumbnail pixel differs, measured in full.
    auto changed = frame;
    for (int y = 38; y < 40; ++y) {
        for (int x = 0; x < 2; ++x) {
            changed.rgba[(static_cast<std::size_t>(y) * 64 + static_cast<std::size_t>(x)) * 4] = 0;
        }
    }
    ShownComparison other(rec, model, 2.0);
    ASSERT_TRUE(other.add(5, 5000, 64, 40, changed.rgba));
    ASSERT_EQ(other.measured().size(), 1u);
    EXPECT_GT(other.measured()[0].stats.max, 0.0);
    EXPECT_EQ(other.measured()[0].stats.pixels, 32u * 20u);
}

} // namespace
} // namespace replica::platform
