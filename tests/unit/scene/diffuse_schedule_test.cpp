// The cached diffuse term's refresh schedule (pipeline/scene/diffuse_schedule.h), written out by
// hand frame by frame for K = 3 and K = 1.
#include <algorithm>
#include <limits>
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
              (DiffuseDraw{0.3, std::nullopt, std::nullopt, 0.0}));
    EXPECT_EQ(diffuseDraw(DiffuseTilt{0.0, std::nullopt, 0}, {0.2, std::nullopt, 0}, false, 1),
              (DiffuseDraw{0.2, std::nullopt, std::nullopt, 0.0}));
}

// Tilt nodes, frame by frame with K = 2 (unless given), a step of 1 and a lag bound of 1.5
// (radians, numbers chosen to be exact in binary where they are compared).
struct NodeFrame {
    double held;
    int direction;
    std::vector<double> nodes; // after the frame
    DiffuseDraw draw;
};
void expectNodeFrames(const std::vector<NodeFrame>& frames,
                      const std::vector<int>& lightChanges,
                      int k = 2)
{
    std::optional<DiffuseNodes> last;
    for (std::size_t f = 0; f < frames.size(); ++f) {
        const NodeFrame& e = frames[f];
        const bool changed = std::find(lightChanges.begin(), lightChanges.end(),
                                       static_cast<int>(f)) != lightChanges.end();
        const DiffuseNodeStep got =
                nextDiffuseNodes(last, e.held, changed, k, 1.0, 1.5, e.direction);
        EXPECT_EQ(got.nodes.nodes, e.nodes) << "frame " << f;
        EXPECT_EQ(got.draw.shownRad, e.draw.shownRad) << "frame " << f;
        EXPECT_EQ(got.draw.band, e.draw.band) << "frame " << f;
        EXPECT_EQ(got.draw.mixRad, e.draw.mixRad) << "frame " << f;
        EXPECT_NEAR(got.draw.mix, e.draw.mix, 1e-12) << "frame " << f;
        last = got.nodes;
    }
}

TEST(DiffuseNodes, AMovingTiltIsShownBetweenTheNodesAroundItEachDrawnInKBands)
{
    const auto none = std::nullopt;
    expectNodeFrames(
            {
                    // The first frame: the held tilt whole, the one node; still: nothing more.
                    {0.375, 0, {0.375}, {0.375, none, none, 0.0}},
                    {0.375, 0, {0.375}, {0.375, none, none, 0.0}},
                    // Off the node, nothing above it: the nearer end of its step (1), in two
                    // bands, the nearest node shown meanwhile.
                    {0.75, 1, {0.375}, {0.375, DiffuseBand{1.0, 0, 2}, none, 0.0}},
                    {0.875, 1, {0.375, 1.0}, {0.375, DiffuseBand{1.0, 1, 2}, 1.0, 0.8}},
                    // Spanned, moving up: the next multiple past the nodes, 2.
                    {0.9375, 1, {0.375, 1.0}, {0.375, DiffuseBand{2.0, 0, 2}, 1.0, 0.9}},
                    {1.25, 1, {0.375, 1.0, 2.0}, {1.0, DiffuseBand{2.0, 1, 2}, 2.0, 0.25}},
                    {1.5, 1, {0.375, 1.0, 2.0}, {1.0, DiffuseBand{3.0, 0, 2}, 2.0, 0.5}},
                    // Still: the refresh under way finishes, no other starts.
                    {1.5, 0, {0.375, 1.0, 2.0, 3.0}, {1.0, DiffuseBand{3.0, 1, 2}, 2.0, 0.5}},
                    {1.5, 0, {0.375, 1.0, 2.0, 3.0}, {1.0, none, 2.0, 0.5}},
                    // Moving down from (1, 2): the first multiple below the nodes that span it.
                    {1.25, -1, {0.375, 1.0, 2.0, 3.0}, {1.0, DiffuseBand{0.0, 0, 2}, 2.0, 0.25}},
                    // Its last band makes five nodes: the farthest from 1.25 (3) is forgotten.
                    {1.25, -1, {0.375, 1.0, 2.0, 0.0}, {1.0, DiffuseBand{0.0, 1, 2}, 2.0, 0.25}},
                    // 3 is gone: 3.625 is 1.625 from the nearest node (2), past the bound, so
                    // it is drawn whole at once; 0, farthest, is forgotten.
                    {3.625, 1, {0.375, 1.0, 2.0, 3.625}, {3.625, none, none, 0.0}},
                    // On its own node, moving up: the next multiple, 4.
                    {3.625,
                     1,
                     {0.375, 1.0, 2.0, 3.625},
                     {3.625, DiffuseBand{4.0, 0, 2}, none, 0.0}},
                    // 4 completes: five nodes, and the farthest from 3.75 (0.375) is forgotten.
                    {3.75,
                     1,
                     {1.0, 2.0, 3.625, 4.0},
                     {3.625, DiffuseBand{4.0, 1, 2}, 4.0, 1.0 / 3.0}},
            },
            {0});
}

TEST(DiffuseNodes, AFarMoveIsDrawnWholeAndANewLightStartsAgain)
{
    const auto none = std::nullopt;
    // K = 3.
    expectNodeFrames(
            {
                    {0.0, 0, {0.0}, {0.0, none, none, 0.0}},
                    // 0.5 from the node: 1 (the nearer end not held) in bands.
                    {0.5, 0, {0.0}, {0.0, DiffuseBand{1.0, 0, 3}, none, 0.0}},
                    // 5.25 away: whole at once, the refresh dropped after one band of three.
                    {5.25, 0, {0.0, 5.25}, {5.25, none, none, 0.0}},
                    {5.25, 0, {0.0, 5.25}, {5.25, none, none, 0.0}},
                    // A new light: the held tilt whole, every node forgotten.
                    {5.5, 0, {5.5}, {5.5, none, none, 0.0}},
            },
            {0, 4}, 3);
    // K = 2: the far move comes on the frame whose band completes 1, which is drawn and kept.
    expectNodeFrames(
            {
                    {0.0, 0, {0.0}, {0.0, none, none, 0.0}},
                    {0.5, 0, {0.0}, {0.0, DiffuseBand{1.0, 0, 2}, none, 0.0}},
                    {5.25, 0, {0.0, 1.0, 5.25}, {5.25, DiffuseBand{1.0, 1, 2}, none, 0.0}},
            },
            {0});
}

TEST(DiffuseNodes, NoStepOrANonFiniteTiltDrawsTheHeldTiltWhole)
{
    const DiffuseNodes some{{0.0, 1.0}, std::nullopt, 0};
    for (const double step : {0.0, -1.0, std::numeric_limits<double>::quiet_NaN()}) {
        const auto got = nextDiffuseNodes(some, 0.5, false, 3, step, 1.5, 0);
        EXPECT_EQ(got.draw.shownRad, 0.5);
        EXPECT_FALSE(got.draw.mixRad);
        EXPECT_EQ(got.nodes.nodes, std::vector<double>{0.5});
    }
    // Between two nodes a step apart: interpolated, nothing drawn.
    const auto mid = nextDiffuseNodes(some, 0.25, false, 3, 1.0, 1.5, 0);
    EXPECT_EQ(mid.draw.mixRad, std::optional<double>(1.0));
    EXPECT_DOUBLE_EQ(mid.draw.mix, 0.25);
    EXPECT_FALSE(mid.draw.band);
}

} // namespace
} // namespace replica::pipeline::scene
