// The cached diffuse term's refresh schedule (pipeline/scene/diffuse_schedule.h), written out by
// hand frame by frame for K = 3 and K = 1.
#include <optional>
#include <vector>

#include <pipeline/scene/diffuse_schedule.h>

#include <gtest/gtest.h>

namespace replica::pipeline::scene {
namespace {

TEST(DiffuseSchedule, ANewHeldTiltIsDrawnInKBandsAndAMoveMeanwhileWaits)
{
    const int k = 3;
    // Held tilts of frames 0..7: a move at frame 2 (0.1), another at frame 3 (0.2) while the
    // first refresh is under way.
    const std::vector<double> held{0.0, 0.0, 0.1, 0.2, 0.2, 0.2, 0.2, 0.2};
    const std::vector<DiffuseTilt> expect{
            {0.0, std::nullopt, 0}, // the first frame: whole, at the held tilt
            {0.0, std::nullopt, 0}, // nothing moved
            {0.0, 0.1, 1},          // refresh toward 0.1, band 1 of 3 drawn
            {0.0, 0.1, 2},          // 0.2 waits
            {0.1, std::nullopt, 0}, // band 3: 0.1 shown
            {0.1, 0.2, 1},          // then 0.2's refresh starts
            {0.1, 0.2, 2},          {0.2, std::nullopt, 0},
    };
    std::optional<DiffuseTilt> last;
    for (std::size_t f = 0; f < held.size(); ++f) {
        const DiffuseTilt d = nextDiffuse(last, held[f], false, k);
        EXPECT_EQ(d, expect[f]) << "frame " << f;
        if (last) {
            EXPECT_TRUE(diffuseFollows(*last, d, k)) << "frame " << f;
        }
        last = d;
    }
    // Two frames on is no single draw, nor is a refresh toward another tilt or a band skipped.
    EXPECT_FALSE(diffuseFollows(expect[2], expect[4], k));
    EXPECT_FALSE(diffuseFollows(expect[2], {0.0, 0.2, 2}, k));
    EXPECT_FALSE(diffuseFollows(expect[1], {0.0, 0.1, 2}, k));
    EXPECT_DOUBLE_EQ(diffuseTarget(expect[3]), 0.1);
    EXPECT_DOUBLE_EQ(diffuseTarget(expect[4]), 0.1);
}

TEST(DiffuseSchedule, ANewLightOrOneBandIsDrawnWhole)
{
    const DiffuseTilt underWay{0.0, 0.1, 1};
    EXPECT_EQ(nextDiffuse(underWay, 0.3, true, 3), (DiffuseTilt{0.3, std::nullopt, 0}));
    // K = 1 (and below 1, counted as 1): a new held tilt is shown at once.
    EXPECT_EQ(nextDiffuse(DiffuseTilt{0.0, std::nullopt, 0}, 0.2, false, 1),
              (DiffuseTilt{0.2, std::nullopt, 0}));
    EXPECT_EQ(nextDiffuse(DiffuseTilt{0.0, std::nullopt, 0}, 0.2, false, 0),
              (DiffuseTilt{0.2, std::nullopt, 0}));
    EXPECT_TRUE(diffuseFollows({0.0, std::nullopt, 0}, {0.2, std::nullopt, 0}, 1));
    EXPECT_FALSE(diffuseFollows({0.0, std::nullopt, 0}, {0.2, std::nullopt, 0}, 3));
}

} // namespace
} // namespace replica::pipeline::scene
