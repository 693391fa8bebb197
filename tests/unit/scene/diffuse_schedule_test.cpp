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
    // What each frame draws, by hand: the term shown and "band b of K toward T".
    const std::vector<DiffuseDraw> draws{
            {0.0, std::nullopt},           {0.0, std::nullopt},
            {0.0, DiffuseBand{0.1, 0, 3}}, {0.0, DiffuseBand{0.1, 1, 3}},
            {0.1, DiffuseBand{0.1, 2, 3}}, // the last band: 0.1 shown from this frame
            {0.1, DiffuseBand{0.2, 0, 3}}, {0.1, DiffuseBand{0.2, 1, 3}},
            {0.2, DiffuseBand{0.2, 2, 3}},
    };
    std::optional<DiffuseTilt> last;
    for (std::size_t f = 0; f < held.size(); ++f) {
        const DiffuseTilt d = nextDiffuse(last, held[f], false, k);
        EXPECT_EQ(d, expect[f]) << "frame " << f;
        EXPECT_EQ(diffuseDraw(last, d, false, k), draws[f]) << "frame " << f;
        last = d;
    }
}

// The same moves with a lag bound of 0.15: frame 3's held tilt (0.2) is 0.2 from the term shown
// (0.0), so the refresh toward 0.1 is dropped and 0.2 drawn whole at once; frame 2's 0.1 is
// within the bound and refreshed in bands as before.
TEST(DiffuseSchedule, ATermLaggingMoreThanTheBoundIsDrawnWholeAtOnce)
{
    const int k = 3;
    const double bound = 0.15;
    const std::vector<double> held{0.0, 0.0, 0.1, 0.2, 0.2, 0.34, 0.34, 0.34};
    const std::vector<DiffuseTilt> expect{
            {0.0, std::nullopt, 0}, {0.0, std::nullopt, 0},
            {0.0, 0.1, 1},          // within the bound: banded
            {0.2, std::nullopt, 0}, // 0.2 from the shown 0.0: whole, the refresh dropped
            {0.2, std::nullopt, 0}, {0.2, 0.34, 1}, // 0.14 from the shown 0.2: within the bound
            {0.2, 0.34, 2},         {0.34, std::nullopt, 0},
    };
    const std::vector<DiffuseDraw> draws{
            {0.0, std::nullopt},
            {0.0, std::nullopt},
            {0.0, DiffuseBand{0.1, 0, 3}},
            {0.2, std::nullopt}, // whole: no band, not the dropped refresh's last
            {0.2, std::nullopt},
            {0.2, DiffuseBand{0.34, 0, 3}},
            {0.2, DiffuseBand{0.34, 1, 3}},
            {0.34, DiffuseBand{0.34, 2, 3}},
    };
    std::optional<DiffuseTilt> last;
    for (std::size_t f = 0; f < held.size(); ++f) {
        const DiffuseTilt d = nextDiffuse(last, held[f], false, k, bound);
        EXPECT_EQ(d, expect[f]) << "frame " << f;
        EXPECT_EQ(diffuseDraw(last, d, false, k), draws[f]) << "frame " << f;
        last = d;
    }
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
    // Drawn whole: no band, neither for a new light in the middle of a refresh nor with K = 1.
    EXPECT_EQ(diffuseDraw(underWay, {0.3, std::nullopt, 0}, true, 3),
              (DiffuseDraw{0.3, std::nullopt}));
    EXPECT_EQ(diffuseDraw(DiffuseTilt{0.0, std::nullopt, 0}, {0.2, std::nullopt, 0}, false, 1),
              (DiffuseDraw{0.2, std::nullopt}));
}

} // namespace
} // namespace replica::pipeline::scene
