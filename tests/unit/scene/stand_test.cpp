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
        const glm::dvec3 x = glm::normalize(p.rightM);
        const glm::dvec3 y = glm::normalize(p.upM);
        EXPECT_NEAR(glm::dot(x, y), 0.0, 1e-12);
        EXPECT_NEAR(glm::dot(y, p.normal), 0.0, 1e-12);
        EXPECT_NEAR(glm::length(glm::cross(x, y) - p.normal), 0.0, 1e-12);
        EXPECT_NEAR(glm::length(p.rightM), stand.panelWidthM, 1e-12);
        EXPECT_NEAR(glm::length(p.upM), stand.panelHeightM, 1e-12);
        // The bottom edge's midpoint sits hingeToPanel above the hinge, along the panel.
        const glm::dvec3 bottomMid = p.originM + 0.5 * p.rightM;
        EXPECT_NEAR(glm::length(bottomMid - stand.hingeM), stand.hingeToPanelM, 1e-12);
    }
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
