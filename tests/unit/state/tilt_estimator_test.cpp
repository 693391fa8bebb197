// The tilt estimator's hold filter and sliced refresh, against the schedule worked out by hand: a
// step of 1 degree enters the 16-frame mean 1/16 degree a frame, so the mean passes the 0.15-degree
// hold on the 3rd frame after the step (3/16 > 0.15 > 2/16), and again every 3 frames after the
// last re-take, until the mean settles within 1/16 degree of the step; each new held tilt shows K
// frames after it was taken (the frame that draws the refresh's last band).
#include <cmath>
#include <numbers>
#include <optional>

#include <nlohmann/json.hpp>
#include <state/tilt_estimator.h>

#include <gtest/gtest.h>

namespace replica::state {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

pipeline::scene::SceneState frame(TiltEstimator& t, double tilt, bool lightChanged = false)
{
    pipeline::scene::SceneState st;
    st.lightChanged = lightChanged;
    t.sense(tilt);
    t.write(st);
    return st;
}

TEST(TiltEstimator, AStepIsHeldThenShownKFramesAfterEachReTake)
{
    const double a = 0.3;
    const double b = a + 1.0 * kDeg;
    ASSERT_GT(3.0 / 16.0 * kDeg, kTiltHoldRad);
    ASSERT_LT(2.0 / 16.0 * kDeg, kTiltHoldRad);
    for (const int k : {1, 3}) {
        TiltEstimator t({0.0, k});
        auto st = frame(t, a, true);
        ASSERT_TRUE(st.diffuse);
        EXPECT_EQ(st.diffuse->shownRad, a);
        for (int i = 0; i < 20; ++i) {
            st = frame(t, a);
        }
        EXPECT_EQ(st.heldTiltRad, a);
        EXPECT_EQ(st.diffuse->shownRad, a);
        EXPECT_FALSE(st.diffuse->band);
        // j: frames since the step (the step's own frame is j = 1).
        double shownWant = a;
        int refreshSince = -1; // the frame the refresh under way was taken (-1: none)
        double heldWant = a;
        for (int j = 1; j <= 24; ++j) {
            st = frame(t, b);
            EXPECT_NEAR(st.tiltRad, b, 0.0) << j;
            // The held tilt: re-taken at j = 3, 6, 9, 12 and 15 (a + j/16 degree), then kept.
            if (j <= 15 && j % 3 == 0) {
                heldWant = a + j / 16.0 * kDeg;
                refreshSince = j;
            }
            EXPECT_NEAR(st.heldTiltRad, heldWant, 1e-12) << "frame " << j << ", K " << k;
            // Band j - refreshSince of K drawn this frame (with K > 1); shown K - 1 frames after
            // it was taken, in the frame that draws its last band.
            const int bandWant = refreshSince >= 0 && k > 1 ? j - refreshSince : -1;
            if (refreshSince >= 0 && j - refreshSince == k - 1) {
                shownWant = heldWant;
                refreshSince = -1;
            }
            EXPECT_NEAR(st.diffuse->shownRad, shownWant, 1e-12) << "frame " << j << ", K " << k;
            EXPECT_EQ(st.diffuse->band.has_value(), bandWant >= 0) << "frame " << j << ", K " << k;
            if (bandWant >= 0 && st.diffuse->band) {
                EXPECT_NEAR(st.diffuse->band->towardRad, heldWant, 1e-12) << j;
                EXPECT_EQ(st.diffuse->band->band, bandWant) << j;
                EXPECT_EQ(st.diffuse->band->bands, k) << j;
            }
        }
        EXPECT_NEAR(st.diffuse->shownRad, a + 15.0 / 16.0 * kDeg, 1e-12);
        // A new light takes the mean at once (the renderer draws the diffuse term whole).
        st = frame(t, b, true);
        EXPECT_NEAR(st.heldTiltRad, b, 1e-12);
        EXPECT_EQ(st.diffuse->shownRad, st.heldTiltRad);
        EXPECT_FALSE(st.diffuse->band);
    }
}

TEST(TiltEstimator, NonFiniteTiltsStayOutOfTheMean)
{
    TiltEstimator t({0.0, 1});
    frame(t, 0.4, true);
    const auto st = frame(t, std::nan(""));
    // The specular term's tilt is decided here, once: the held tilt stands in for it.
    EXPECT_EQ(st.tiltRad, 0.4);
    EXPECT_EQ(st.heldTiltRad, 0.4);
    EXPECT_EQ(st.diffuse->shownRad, 0.4);
}

TEST(TiltEstimator, SaveAndRestoreRefuseWhatCannotBe)
{
    TiltEstimator t({0.0, 3});
    frame(t, 0.4, true);
    auto saved = t.save();
    TiltEstimator u({0.0, 3});
    ASSERT_TRUE(u.restore(saved));
    EXPECT_EQ(u.save(), saved);
    saved["refresh_bands"] = 3; // a refresh in 3 bands never has 3 drawn: it is shown then
    saved["refresh_rad"] = 0.5;
    auto bad = u.restore(saved);
    ASSERT_FALSE(bad);
    EXPECT_EQ(bad.error().message, "tilt: 3 bands drawn of a refresh in 3");
}

} // namespace
} // namespace replica::state
