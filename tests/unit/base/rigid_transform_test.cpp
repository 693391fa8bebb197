// T_booth_tracker as one rigid transform (pipeline/base/rigid_transform.h): closed-form rotations
// and translations, the inverse, the x-then-y-then-z angle convention, and the default mounting.
#include <cmath>
#include <numbers>
#include <random>

#include <glm/geometric.hpp>

#include <pipeline/base/rigid_transform.h>

#include <gtest/gtest.h>

namespace replica::tests {
namespace {

using pipeline::RigidTransform;

TEST(RigidTransform, AQuarterTurnAboutZAndATranslationInClosedForm)
{
    // Rz(90 deg): x -> y, y -> -x; then + t.
    const RigidTransform t = pipeline::rigidFromDegrees({0.0, 0.0, 90.0}, {1.0, 2.0, 3.0});
    const glm::dvec3 a = t.apply({1.0, 0.0, 0.0});
    EXPECT_NEAR(a.x, 1.0, 1e-15);
    EXPECT_NEAR(a.y, 3.0, 1e-15);
    EXPECT_NEAR(a.z, 3.0, 1e-15);
    const glm::dvec3 b = t.apply({0.0, 2.0, 0.5});
    EXPECT_NEAR(b.x, 1.0 - 2.0, 1e-15);
    EXPECT_NEAR(b.y, 2.0, 1e-15);
    EXPECT_NEAR(b.z, 3.5, 1e-15);
}

TEST(RigidTransform, AnglesTurnAboutXThenYThenZ)
{
    // Rx(90) takes +z to -y; Ry(90) leaves -y; Rz(90) takes -y to +x. Applying z first would
    // give +x -> ... a different answer: (0, -1, 0).
    const glm::dmat3 r = pipeline::rotationXyz({std::numbers::pi / 2, 0.0, std::numbers::pi / 2});
    const glm::dvec3 v = r * glm::dvec3(0.0, 0.0, 1.0);
    EXPECT_NEAR(v.x, 1.0, 1e-15);
    EXPECT_NEAR(v.y, 0.0, 1e-15);
    EXPECT_NEAR(v.z, 0.0, 1e-15);
    // Ry(theta) about y in closed form: (cos, 0, -sin) for +x.
    const double th = 0.3;
    const glm::dvec3 w = pipeline::rotationXyz({0.0, th, 0.0}) * glm::dvec3(1.0, 0.0, 0.0);
    EXPECT_NEAR(w.x, std::cos(th), 1e-15);
    EXPECT_NEAR(w.y, 0.0, 1e-15);
    EXPECT_NEAR(w.z, -std::sin(th), 1e-15);
    EXPECT_EQ(pipeline::rotationXyz(glm::dvec3(0.0)), glm::dmat3(1.0)); // exact identity
}

TEST(RigidTransform, InverseRoundTripsAndComposesToTheIdentity)
{
    std::mt19937_64 rng(20);
    std::uniform_real_distribution<double> angle(-180.0, 180.0);
    std::uniform_real_distribution<double> metres(-2.0, 2.0);
    for (int i = 0; i < 200; ++i) {
        const RigidTransform t = pipeline::rigidFromDegrees(
                {angle(rng), angle(rng), angle(rng)}, {metres(rng), metres(rng), metres(rng)});
        EXPECT_TRUE(pipeline::isRotation(t.rotation, 1e-12));
        const glm::dvec3 p{metres(rng), metres(rng), metres(rng)};
        EXPECT_LT(glm::length(t.applyInverse(t.apply(p)) - p), 1e-14);
        EXPECT_LT(glm::length(t.inverse().apply(t.apply(p)) - p), 1e-14);
        EXPECT_LT(glm::length(t.apply(t.inverse().apply(p)) - p), 1e-14);
        // A rigid transform keeps distances.
        const glm::dvec3 q{metres(rng), metres(rng), metres(rng)};
        EXPECT_NEAR(glm::length(t.apply(p) - t.apply(q)), glm::length(p - q), 1e-14);
    }
}

TEST(RigidTransform, TheDefaultIsTheFixedMountingAndAddsItsTranslationExactly)
{
    const RigidTransform d = pipeline::defaultTrackerInBooth();
    EXPECT_EQ(d.rotation, glm::dmat3(1.0));
    EXPECT_EQ(d.translation, glm::dvec3(0.0, 0.42, 0.05));
    EXPECT_EQ(pipeline::rigidFromDegrees(glm::dvec3(0.0), {0.0, 0.42, 0.05}), d);
    // Bit for bit what the code did before it was a transform: eye + translation.
    std::mt19937_64 rng(21);
    std::uniform_real_distribution<double> metres(-1.0, 1.0);
    for (int i = 0; i < 1000; ++i) {
        const glm::dvec3 e{metres(rng), metres(rng), metres(rng)};
        EXPECT_EQ(d.apply(e), e + glm::dvec3(0.0, 0.42, 0.05));
        EXPECT_EQ(d.applyInverse(e), e - glm::dvec3(0.0, 0.42, 0.05));
    }
}

TEST(RigidTransform, MirrorsAndSkewsAreNotRotations)
{
    EXPECT_TRUE(pipeline::isRotation(glm::dmat3(1.0)));
    glm::dmat3 mirror(1.0);
    mirror[0][0] = -1.0;
    EXPECT_FALSE(pipeline::isRotation(mirror));
    glm::dmat3 skew(1.0);
    skew[1][0] = 0.01;
    EXPECT_FALSE(pipeline::isRotation(skew));
    glm::dmat3 nan(1.0);
    nan[2][2] = std::nan("");
    EXPECT_FALSE(pipeline::isRotation(nan));
}

} // namespace
} // namespace replica::tests
