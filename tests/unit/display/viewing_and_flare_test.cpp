// Viewing-angle compensation and front-surface reflection against closed forms and the paper's
// two measured points.
#include <cmath>
#include <numbers>

#include <pipeline/display/display_inverse.h>
#include <pipeline/display/xyz_difference.h>
#include <pipeline/offline/display/synthetic_display.h>

#include <gtest/gtest.h>

#include "display_test_support.h"

namespace replica::pipeline::display {
namespace {

TEST(ViewingAngle, TableHoldsThePapersPoints)
{
    const ViewingAngleTable t = wideIpsViewingAngles();
    ASSERT_TRUE(t.validate().has_value());
    const glm::dvec3 white{950.0, 1000.0, 1089.0};
    EXPECT_NEAR(viewingGain(t, white, 0.0).y, 1.0, 1e-12);
    EXPECT_NEAR(viewingGain(t, white, 15.0).y, 0.90, 1e-12); // paper: ~90 % at 15 deg
    EXPECT_NEAR(viewingGain(t, white, 25.0).y, 0.75, 1e-12); // paper: ~75 % at 25 deg
    EXPECT_NEAR(viewingGain(t, white, 20.0).y, 0.83, 1e-12);
    // Beyond the table the last row holds; an eye behind the panel reads the last row too.
    EXPECT_NEAR(viewingGain(t, white, 89.0).y, t.luminanceRatio.back(), 1e-12);
    EXPECT_NEAR(viewingGain(t, white, std::nan("")).y, t.luminanceRatio.back(), 1e-12);
    // At 0 deg the white's chromaticity is unchanged: all gains 1.
    const glm::dvec3 g0 = viewingGain(t, white, 0.0);
    EXPECT_NEAR(g0.x, 1.0, 1e-12);
    EXPECT_NEAR(g0.z, 1.0, 1e-12);
    // The shipped table shifts white towards blue off axis: Z gains more than Y.
    const glm::dvec3 g30 = viewingGain(t, white, 30.0);
    EXPECT_GT(g30.z / g30.y, 1.0);
    EXPECT_TRUE(viewingGain(ViewingAngleTable{}, white, 40.0) == glm::dvec3(1.0));
}

TEST(ViewingAngle, PerPixelAngleFromEyePosition)
{
    const glm::dvec3 n{0.0, 0.0, 1.0};
    EXPECT_NEAR(viewingAngleDeg({0, 0, 0}, n, {0, 0, 0.6}), 0.0, 1e-12);
    EXPECT_NEAR(viewingAngleDeg({0.3, 0, 0}, n, {0, 0, 0.3}), 45.0, 1e-9);
    EXPECT_NEAR(viewingAngleDeg({0, 0, 0}, n,
                                {0, 0.6 * std::tan(25.0 * std::numbers::pi / 180.0), 0.6}),
                25.0, 1e-9);
    EXPECT_DOUBLE_EQ(viewingAngleDeg({0, 0, 0}, n, {0, 0, -0.5}), 90.0); // eye behind
    EXPECT_DOUBLE_EQ(viewingAngleDeg({0, 0, 0}, n, {0.2, 0, 0}), 90.0);  // eye in the plane
    EXPECT_DOUBLE_EQ(viewingAngleDeg({0, 0, 0}, n, {0, 0, 0}), 0.0);     // degenerate, defined
}

TEST(ViewingAngle, CompensationDeliversTheTargetAtTheEye)
{
    const DisplayModel& model = test::fittedSyntheticIps();
    auto inv = DisplayInverse::build(model);
    ASSERT_TRUE(inv.has_value());
    const glm::dvec3 white = model.whiteXyz();
    // A mid-grey and a muted green seen at 15 and 25 deg: emit target / gain, the eye receives
    // gain * forward(counts), which must equal the target.
    for (double angle : {15.0, 25.0}) {
        const glm::dvec3 g = viewingGain(model.viewing, white, angle);
        for (const glm::dvec3& target : {white * 0.2, glm::dvec3(90.0, 150.0, 80.0)}) {
            const auto r = inv->invert(target / g, GamutMode::HueKeeping, ToneInverse::Exact);
            ASSERT_TRUE(r.inGamut());
            const glm::dvec3 atEye = g * model.forward(r.counts);
            EXPECT_LT(deltaE2000Xyz(atEye, target, white), 1e-6);
            // Without compensation the eye sees the loss: about 10 % or 25 % darker.
            const auto raw = inv->invert(target, GamutMode::HueKeeping, ToneInverse::Exact);
            EXPECT_GT(deltaE2000Xyz(g * model.forward(raw.counts), target, white), 2.0);
        }
    }
    // Peak white cannot be compensated off axis: it goes over peak, and is counted.
    const glm::dvec3 g = viewingGain(model.viewing, white, 25.0);
    EXPECT_EQ(inv->invert(white * 0.95 / g).gamutClass, GamutClass::OverPeak);
}

TEST(FrontSurfaceFlare, ClosedFormAndNoDoubleCount)
{
    DisplayModel model = test::fittedSyntheticIps();
    const glm::dvec3 light{1.0985, 1.0, 0.3558}; // illuminant A, Y = 1
    const glm::dvec3 f = frontSurfaceFlareXyz(model, 2000.0, light);
    EXPECT_NEAR(f.y, 0.002 * 2000.0 / std::numbers::pi, 1e-12); // 1.273 cd/m^2
    EXPECT_NEAR(f.x / f.y, light.x, 1e-12);
    EXPECT_EQ(frontSurfaceFlareXyz(model, 0.0, light), glm::dvec3(0.0));
    EXPECT_EQ(frontSurfaceFlareXyz(model, -5.0, light), glm::dvec3(0.0));
    model.condition = MeasurementCondition::LitBooth;
    EXPECT_EQ(frontSurfaceFlareXyz(model, 2000.0, light), glm::dvec3(0.0));
}

} // namespace
} // namespace replica::pipeline::display
