// Sample-to-scene conversion: lamp classification, eye in the booth frame, tilt, and holding the
// last good value when a sample is unusable (NaN pose, lost tracking, undefined tilt, saturated
// spectrum).
#include <cmath>
#include <limits>

#include <hal/sim/sim_devices.h>
#include <pipeline/base/data_dir.h>
#include <pipeline/colour/spectral_table.h>
#include <platform/loop/scene_updater.h>

#include <gtest/gtest.h>

namespace replica::platform {
namespace {

class SceneUpdaterTest : public ::testing::Test
{
protected:
    void SetUp() override
    {
        auto booth = pipeline::scene::loadDefaultBooth(dataDir().string());
        ASSERT_TRUE(booth);
        auto cal = pipeline::spectral::loadSpectrometerCalibration(dataDir() / "spectrometer" /
                                                                   "sim_usb2000_responsivity.csv");
        ASSERT_TRUE(cal);
        setup_.booth = *booth;
        setup_.calibration = *cal;
        // Raw counts of the D65 simulator (lamp 2) from the simulated spectrometer.
        auto table = pipeline::colour::loadSpectralCsv(dataDir() / "spectra" /
                                                       "cie_illuminants_F1_F12_5nm_380_780.csv");
        ASSERT_TRUE(table);
        hal::sim::SimLamp f7{"F7", table->wavelengthNm, {}};
        for (const auto& row : table->rows) {
            f7.power.push_back(row[6]);
        }
        hal::sim::ScenarioParams scenario;
        scenario.lampCount = 1;
        hal::sim::SimSpectrometerParams p;
        p.lamps = {f7};
        p.responsivityNm = cal->wavelengthNm;
        p.responsivity = cal->responsivity;
        std::vector<hal::SpectrumSample> out;
        hal::sim::makeSimSpectrometer(scenario, p)->poll(400'000'000, out);
        ASSERT_EQ(out.size(), 2u);
        spectra_ = out;
    }

    SceneUpdaterSetup setup_;
    std::vector<hal::SpectrumSample> spectra_;
};

TEST_F(SceneUpdaterTest, ClassifiesTheLampAndUsesItsStoredSpectrumAndLuminance)
{
    SceneUpdater u(setup_);
    pipeline::scene::SceneState st;
    u.update(st, &spectra_[0], nullptr, nullptr);
    EXPECT_EQ(st.lampIndex, 2);
    EXPECT_EQ(st.illuminant.v, setup_.booth.lamps[2].spectrum.v);
    EXPECT_EQ(st.emitterLuminanceCdM2, setup_.booth.lamps[2].luminanceCdM2);
}

TEST_F(SceneUpdaterTest, SaturatedSpectrumKeepsTheLastLight)
{
    SceneUpdater u(setup_);
    pipeline::scene::SceneState st;
    u.update(st, &spectra_[0], nullptr, nullptr);
    hal::SpectrumSample saturated = spectra_[1];
    saturated.saturated = true;
    saturated.counts.assign(saturated.counts.size(), 65535);
    u.update(st, &saturated, nullptr, nullptr);
    EXPECT_EQ(st.lampIndex, 2);
    EXPECT_EQ(u.rejectedSpectra(), 1u);
}

TEST_F(SceneUpdaterTest, EyeMovesIntoTheBoothFrameAndHoldsThroughNaNAndLostTracking)
{
    SceneUpdater u(setup_);
    pipeline::scene::SceneState st;
    hal::PoseSample p;
    p.sequence = 1;
    p.tracked = true;
    p.eyeTrackerM = {0.1, 0.05, 0.5};
    u.update(st, nullptr, &p, nullptr);
    const glm::dvec3 expected = p.eyeTrackerM + setup_.trackerInBoothM;
    EXPECT_EQ(st.eyeBoothM, expected);

    hal::PoseSample nan = p;
    nan.sequence = 2;
    nan.eyeTrackerM.x = std::numeric_limits<double>::quiet_NaN();
    u.update(st, nullptr, &nan, nullptr);
    EXPECT_EQ(st.eyeBoothM, expected);

    hal::PoseSample lost = p;
    lost.sequence = 3;
    lost.tracked = false;
    lost.eyeTrackerM = {5.0, 5.0, 5.0};
    u.update(st, nullptr, &lost, nullptr);
    EXPECT_EQ(st.eyeBoothM, expected);
    EXPECT_EQ(u.rejectedPoses(), 2u);
}

TEST_F(SceneUpdaterTest, TiltHoldsWhenGravityIsAlongTheHinge)
{
    SceneUpdater u(setup_);
    pipeline::scene::SceneState st;
    hal::AccelSample a;
    a.sequence = 1;
    a.gravity = {0.0, -9.80665 * std::cos(0.3), -9.80665 * std::sin(0.3)};
    u.update(st, nullptr, nullptr, &a);
    EXPECT_NEAR(st.tiltRad, 0.3, 1e-12);
    hal::AccelSample along = a;
    along.sequence = 2;
    along.gravity = {9.80665, 0.0, 0.0};
    u.update(st, nullptr, nullptr, &along);
    EXPECT_NEAR(st.tiltRad, 0.3, 1e-12);
    EXPECT_EQ(u.rejectedTilts(), 1u);
}

} // namespace
} // namespace replica::platform
