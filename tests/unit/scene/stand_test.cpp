// Stand geometry and tilt from gravity, including the undefined cases (hard case 14).
#include <cmath>
#include <limits>
#include <numbers>

#include <glm/geometric.hpp>

#include <pipeline/scene/stand.h>

#include <gtest/gtest.h>

namespace replica::pipeline::scene {
namespace {

constexpr double kG = 9.80665;

TEST(Stand, PanelFrameIsOrthonormalAndRightHanded)
{
    StandModel stand;
    for (double tilt : {-0.5, 0.0, 0.3, 1.2}) {
        const PanelPose p = panelPose(stand, tilt);
        const glm::dvec3 x = glm::normalize(p.rightEdgeM());
        const glm::dvec3 y = glm::normalize(p.upEdgeM());
        EXPECT_NEAR(glm::dot(x, y), 0.0, 1e-12);
        EXPECT_NEAR(glm::dot(y, p.normal), 0.0, 1e-12);
        EXPECT_NEAR(glm::length(glm::cross(x, y) - p.normal), 0.0, 1e-12);
        EXPECT_NEAR(glm::length(p.rightEdgeM()), stand.panelWidthM, 1e-12);
        EXPECT_NEAR(glm::length(p.upEdgeM()), stand.panelHeightM, 1e-12);
        // The bottom edge's midpoint sits hingeToPanel above the hinge, along the panel.
        const glm::dvec3 bottomMid = p.cornerM() + 0.5 * p.rightEdgeM();
        EXPECT_NEAR(glm::length(bottomMid - stand.hingeM), stand.hingeToPanelM, 1e-12);
    }
}

TEST(Stand, ThePanelPoseInClosedForm)
{
    // At tilt t the panel's up is (0, cos t, -sin t) and its normal (0, sin t, cos t); its
    // centre is hingeToPanel + height/2 up the panel from the hinge.
    StandModel stand;
    for (double t : {0.0, 0.25, std::numbers::pi / 6}) {
        const PanelPose p = panelPose(stand, t);
        const glm::dvec3 up{0.0, std::cos(t), -std::sin(t)};
        EXPECT_NEAR(glm::length(p.right - glm::dvec3(1.0, 0.0, 0.0)), 0.0, 1e-15);
        EXPECT_NEAR(glm::length(p.up - up), 0.0, 1e-15);
        EXPECT_NEAR(glm::length(p.normal - glm::dvec3(0.0, std::sin(t), std::cos(t))), 0.0, 1e-15);
        const glm::dvec3 centre =
                stand.hingeM + (stand.hingeToPanelM + 0.5 * stand.panelHeightM) * up;
        EXPECT_NEAR(glm::length(p.centre - centre), 0.0, 1e-15);
        EXPECT_EQ(p.widthM, stand.panelWidthM);
        EXPECT_EQ(p.heightM, stand.panelHeightM);
    }
    // Degrees only at the edges: 30 degrees is pi/6.
    EXPECT_EQ(degreesToRadians(30.0), 30.0 * std::numbers::pi / 180.0);
    EXPECT_NEAR(degreesToRadians(30.0), std::numbers::pi / 6, 1e-15);
    // The default stand's overload.
    EXPECT_EQ(panelPose(0.2).centre, panelPose(StandModel{}, 0.2).centre);
}

TEST(Stand, TiltingBackTurnsTheScreenTowardsTheCeiling)
{
    StandModel stand;
    EXPECT_NEAR(panelPose(stand, 0.0).normal.y, 0.0, 1e-15);
    EXPECT_GT(panelPose(stand, 0.3).normal.y, 0.29);
    EXPECT_LT(panelPose(stand, -0.3).normal.y, -0.29);
}

TEST(TiltFromGravity, RecoversTiltOfTheSimulatedConvention)
{
    for (double tilt = -1.2; tilt <= 1.2; tilt += 0.1) {
        const glm::dvec3 g{0.0, -kG * std::cos(tilt), -kG * std::sin(tilt)};
        auto t = tiltFromGravity(g);
        ASSERT_TRUE(t.has_value());
        EXPECT_NEAR(*t, tilt, 1e-12);
    }
}

TEST(TiltFromGravity, UndefinedAlongTheHingeAxis)
{
    EXPECT_FALSE(tiltFromGravity({kG, 0.0, 0.0}).has_value());
    EXPECT_FALSE(tiltFromGravity({kG * 0.99, 0.05, 0.05}).has_value());
}

TEST(TiltFromGravity, RejectsNaNInfAndImplausibleMagnitude)
{
    const double nan = std::numeric_limits<double>::quiet_NaN();
    EXPECT_FALSE(tiltFromGravity({0.0, nan, -1.0}).has_value());
    EXPECT_FALSE(tiltFromGravity({0.0, -std::numeric_limits<double>::infinity(), 0.0}).has_value());
    EXPECT_FALSE(tiltFromGravity({0.0, 0.0, 0.0}).has_value());       // free fall
    EXPECT_FALSE(tiltFromGravity({0.0, -2.0 * kG, 0.0}).has_value()); // a knock
}

} // namespace
} // namespace replica::pipeline::scene
