// Site calibration: the rigid fit recovers a known T_booth_tracker from synthetic points (exactly
// without noise; within the noise with it, the residual matching the closed-form expectation
// sigma * sqrt((3n - 6) / n) of a 6-parameter fit), and refuses collinear points, a swapped pair
// and a mirror image. The stand fit recovers a known hinge and panel offset from synthetic tilts.
#include <cmath>
#include <random>

#include <glm/geometric.hpp>
#include <glm/matrix.hpp>

#include <pipeline/scene/calibration.h>

#include <gtest/gtest.h>

namespace replica::tests {
namespace {

using namespace pipeline::scene;

glm::dmat3 axisAngle(glm::dvec3 axis, double angle)
{
    axis = glm::normalize(axis);
    const double c = std::cos(angle);
    const double s = std::sin(angle);
    const glm::dmat3 k(0.0, axis.z, -axis.y, -axis.z, 0.0, axis.x, axis.y, -axis.x, 0.0);
    return glm::dmat3(1.0) + s * k + (1.0 - c) * k * k; // Rodrigues
}

double rotationAngle(const glm::dmat3& a, const glm::dmat3& b)
{
    const glm::dmat3 d = glm::transpose(a) * b;
    return std::acos(std::clamp((d[0][0] + d[1][1] + d[2][2] - 1.0) / 2.0, -1.0, 1.0));
}

// Largest element of the difference: exact comparisons (acos near 1 loses half the digits).
double maxDiff(const glm::dmat3& a, const glm::dmat3& b)
{
    double m = 0.0;
    for (int c = 0; c < 3; ++c) {
        for (int r = 0; r < 3; ++r) {
            m = std::max(m, std::abs(a[c][r] - b[c][r]));
        }
    }
    return m;
}

struct Synthetic {
    std::vector<glm::dvec3> tracker;
    std::vector<glm::dvec3> booth;
    pipeline::RigidTransform truth;
};

// Booth points in a 0.6 m box in front of the stand; the tracker sees them through the inverse
// of a known pose, plus Gaussian noise on each tracker coordinate.
Synthetic synthetic(std::size_t n, double sigmaM, unsigned seed)
{
    Synthetic s;
    s.truth.rotation = axisAngle({0.3, 1.0, -0.2}, 2.5);
    s.truth.translation = {0.12, 0.42, -0.05};
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> box(-0.3, 0.3);
    std::normal_distribution<double> noise(0.0, sigmaM);
    for (std::size_t i = 0; i < n; ++i) {
        const glm::dvec3 q{box(rng), 0.45 + box(rng), 0.6 + box(rng)};
        glm::dvec3 p = glm::transpose(s.truth.rotation) * (q - s.truth.translation);
        p += glm::dvec3{noise(rng), noise(rng), noise(rng)};
        s.booth.push_back(q);
        s.tracker.push_back(p);
    }
    return s;
}

TEST(SymmetricEigen, DiagonalisesAKnownMatrix)
{
    const glm::dmat3 r = axisAngle({1.0, 2.0, 3.0}, 0.7);
    const glm::dmat3 d(glm::dvec3{5.0, 0.0, 0.0}, glm::dvec3{0.0, 2.0, 0.0},
                       glm::dvec3{0.0, 0.0, -1.0});
    glm::dvec3 values;
    glm::dmat3 vectors;
    symmetricEigen(r * d * glm::transpose(r), values, vectors);
    EXPECT_NEAR(values[0], 5.0, 1e-12);
    EXPECT_NEAR(values[1], 2.0, 1e-12);
    EXPECT_NEAR(values[2], -1.0, 1e-12);
    for (int k = 0; k < 3; ++k) {
        EXPECT_NEAR(std::abs(glm::dot(vectors[k], r[k])), 1.0, 1e-12);
    }
}

TEST(RigidFit, RecoversTheTransformExactlyWithoutNoise)
{
    const auto s = synthetic(4, 0.0, 1);
    auto fit = fitRigid(s.tracker, s.booth);
    ASSERT_TRUE(fit) << fit.error().message;
    EXPECT_LT(maxDiff(fit->T_booth_tracker.rotation, s.truth.rotation), 1e-12);
    EXPECT_LT(glm::length(fit->T_booth_tracker.translation - s.truth.translation), 1e-12);
    EXPECT_NEAR(glm::determinant(fit->T_booth_tracker.rotation), 1.0, 1e-12);
    EXPECT_LT(fit->rmsM, 1e-12);
}

TEST(RigidFit, ThreePointsSuffice)
{
    const auto s = synthetic(3, 0.0, 2);
    auto fit = fitRigid(s.tracker, s.booth);
    ASSERT_TRUE(fit) << fit.error().message;
    EXPECT_LT(maxDiff(fit->T_booth_tracker.rotation, s.truth.rotation), 1e-12);
}

TEST(RigidFit, WithNoiseTheResidualIsTheNoiseAndThePoseIsWithinIt)
{
    const double sigma = 0.002; // 2 mm per axis, a careful tape and marker
    const std::size_t n = 60;
    const auto s = synthetic(n, sigma, 3);
    auto fit = fitRigid(s.tracker, s.booth);
    ASSERT_TRUE(fit) << fit.error().message;
    // E[sum r^2] = sigma^2 (3n - 6) for a least-squares fit of 6 parameters to 3n coordinates.
    const double expected = sigma * std::sqrt((3.0 * n - 6.0) / static_cast<double>(n));
    EXPECT_NEAR(fit->rmsM, expected, 0.15 * expected);
    // Pose error: of order sigma / sqrt(n) in translation and sigma / (spread sqrt(n)) in angle.
    EXPECT_LT(glm::length(fit->T_booth_tracker.translation - s.truth.translation), 3e-3);
    EXPECT_LT(rotationAngle(fit->T_booth_tracker.rotation, s.truth.rotation), 0.01);
}

TEST(RigidFit, CollinearPointsAreRefused)
{
    std::vector<glm::dvec3> booth;
    std::vector<glm::dvec3> tracker;
    for (int i = 0; i < 5; ++i) {
        booth.push_back(glm::dvec3{0.1, 0.4, 0.5} * static_cast<double>(i));
        // 1 mm off the line: still collinear for calibration purposes.
        tracker.push_back(booth.back() + glm::dvec3{0.0, i % 2 == 0 ? 0.001 : 0.0, 0.0});
    }
    auto fit = fitRigid(tracker, booth);
    ASSERT_FALSE(fit);
    EXPECT_NE(fit.error().message.find("on one line"), std::string::npos) << fit.error().message;
}

TEST(RigidFit, ASwappedPairIsRefusedByItsResidual)
{
    auto s = synthetic(6, 0.001, 4);
    std::swap(s.booth[1], s.booth[4]);
    auto fit = fitRigid(s.tracker, s.booth);
    ASSERT_FALSE(fit);
    EXPECT_NE(fit.error().message.find("RMS residual"), std::string::npos) << fit.error().message;
    // The same points in the right order pass.
    std::swap(s.booth[1], s.booth[4]);
    EXPECT_TRUE(fitRigid(s.tracker, s.booth));
}

TEST(RigidFit, AMirrorImageIsNotFittedWithAReflection)
{
    auto s = synthetic(6, 0.0, 5);
    for (auto& p : s.tracker) {
        p.x = -p.x; // a tracker axis read with the wrong sign
    }
    auto fit = fitRigid(s.tracker, s.booth, {1.0, 0.05});
    ASSERT_TRUE(fit);
    EXPECT_NEAR(glm::determinant(fit->T_booth_tracker.rotation), 1.0, 1e-12);
    EXPECT_GT(fit->rmsM, 0.05); // no rotation maps a mirror image: the residual says so
    EXPECT_FALSE(fitRigid(s.tracker, s.booth));
}

TEST(StandFit, RecoversHingeAndPanelOffsetFromTwoOrThreeTilts)
{
    StandModel truth;
    truth.hingeM = {0.0, 0.18, -0.07};
    truth.hingeToPanelM = 0.035;
    const double g = 9.80665;
    for (const std::vector<double>& tiltsDeg :
         {std::vector<double>{0.0, 30.0}, std::vector<double>{-5.0, 15.0, 40.0}}) {
        std::vector<StandReading> readings;
        for (const double deg : tiltsDeg) {
            const double t = deg * 3.14159265358979323846 / 180.0;
            const PanelPose pose = panelPose(truth, t);
            const glm::dvec3 top = pose.cornerM() + 0.5 * pose.rightEdgeM() + pose.upEdgeM();
            // Gravity in panel axes for tilt t (tiltFromGravity's inverse), the sensor 2 degrees
            // rotated about the panel normal.
            const glm::dvec3 gPanel{0.0, -g * std::cos(t), -g * std::sin(t)};
            const double m = 2.0 * 3.14159265358979323846 / 180.0;
            const glm::dvec3 gSensor{std::cos(m) * gPanel.x - std::sin(m) * gPanel.y,
                                     std::sin(m) * gPanel.x + std::cos(m) * gPanel.y, gPanel.z};
            readings.push_back({gSensor, top.y, top.z});
        }
        auto fit = fitStand(readings, truth.panelWidthM, truth.panelHeightM);
        ASSERT_TRUE(fit) << fit.error().message;
        // The 2-degree mounting error rotates the tilts slightly; the hinge comes back to within
        // a millimetre or two and the axis error is the mounting angle.
        EXPECT_NEAR(fit->axisAngleRad * 180.0 / 3.14159265358979323846, 2.0, 1e-6);
        EXPECT_NEAR(fit->stand.hingeM.y, truth.hingeM.y, 3e-3);
        EXPECT_NEAR(fit->stand.hingeM.z, truth.hingeM.z, 3e-3);
        EXPECT_NEAR(fit->stand.hingeToPanelM, truth.hingeToPanelM, 3e-3);
    }
}

TEST(StandFit, RefusesTiltsTooCloseAndTapeThatDisagrees)
{
    const double g = 9.80665;
    const std::vector<StandReading> close{
            {{0.0, -g, 0.0}, 0.57, -0.07},
            {{0.0, -g * std::cos(0.03), -g * std::sin(0.03)}, 0.57, -0.08}};
    auto fit = fitStand(close, 0.5, 0.3);
    ASSERT_FALSE(fit);
    EXPECT_NE(fit.error().message.find("span only"), std::string::npos);
    const std::vector<StandReading> wrong{
            {{0.0, -g, 0.0}, 0.57, -0.07},
            {{0.0, -g * std::cos(0.5), -g * std::sin(0.5)}, 0.60, -0.30},
            {{0.0, -g * std::cos(0.3), -g * std::sin(0.3)}, 0.40, -0.10}};
    fit = fitStand(wrong, 0.5, 0.3);
    ASSERT_FALSE(fit);
    EXPECT_NE(fit.error().message.find("disagree"), std::string::npos) << fit.error().message;
}

} // namespace
} // namespace replica::tests
