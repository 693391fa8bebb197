// Sample-to-scene conversion: lamp classification, eye in the booth frame, tilt, and holding the
// last good value when a sample is unusable (NaN pose, lost tracking, undefined tilt, saturated
// spectrum).
#include <algorithm>
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
        // Raw counts of the D65 simulator (lamp 2) and of tungsten (lamp 0) from the simulated
        // spectrometer, six of each (1.2 s at five spectra a second).
        auto f = pipeline::colour::loadSpectralCsv(dataDir() / "spectra" /
                                                   "cie_illuminants_F1_F12_5nm_380_780.csv");
        auto a = pipeline::colour::loadSpectralCsv(dataDir() / "spectra" /
                                                   "cie_illuminants_A_D50_D65_5nm_300_780.csv");
        ASSERT_TRUE(f);
        ASSERT_TRUE(a);
        f7_ = sense(*f, "F7", *cal);
        tungsten_ = sense(*a, "A", *cal);
        ASSERT_EQ(f7_.size(), 6u);
        ASSERT_EQ(tungsten_.size(), 6u);
    }

    static std::vector<hal::SpectrumSample>
    sense(const pipeline::colour::SpectralTable& table,
          const std::string& column,
          const pipeline::spectral::SpectrometerCalibration& cal)
    {
        hal::sim::SimLamp lamp{column, table.wavelengthNm, {}};
        const auto c = static_cast<std::size_t>(
                std::find(table.columns.begin(), table.columns.end(), column) -
                table.columns.begin());
        for (const auto& row : table.rows) {
            lamp.power.push_back(c < row.size() ? row[c] : 0.0);
        }
        hal::sim::ScenarioParams scenario;
        scenario.lampCount = 1;
        hal::sim::SimSpectrometerParams p;
        p.lamps = {lamp};
        p.responsivityNm = cal.wavelengthNm;
        p.responsivity = cal.responsivity;
        std::vector<hal::SpectrumSample> out;
        hal::sim::makeSimSpectrometer(scenario, p)->poll(1'200'000'000, out);
        return out;
    }

    SceneUpdater make() const
    {
        auto u = SceneUpdater::create(setup_);
        EXPECT_TRUE(u) << u.error().message;
        return std::move(*u);
    }

    SceneUpdaterSetup setup_;
    std::vector<hal::SpectrumSample> f7_;
    std::vector<hal::SpectrumSample> tungsten_;
};

TEST_F(SceneUpdaterTest, ClassifiesTheLampAndUsesItsStoredSpectrumAndLuminance)
{
    SceneUpdater u = make();
    pipeline::scene::SceneState st;
    const int confirm = pipeline::spectral::LightClassifierParams{}.confirmSamples;
    ASSERT_GE(confirm, 2);
    // Until the lamp has won confirmSamples spectra in a row: direct-sensor mode, the sensed
    // shape at the booth's mean luminance.
    for (int i = 0; i < confirm - 1; ++i) {
        u.update(st, &f7_[static_cast<std::size_t>(i)], nullptr, nullptr);
        EXPECT_EQ(st.lampIndex, -1);
        EXPECT_EQ(u.classification().name, "unknown");
        EXPECT_NE(st.illuminant.v, setup_.booth.lights[2].referenceSpectrum.v);
        EXPECT_GT(st.illuminant[20], 0.0);
        EXPECT_DOUBLE_EQ(st.emitterLuminanceCdM2, (2200.0 + 2600.0 + 2600.0) / 3.0);
    }
    u.update(st, &f7_[static_cast<std::size_t>(confirm - 1)], nullptr, nullptr);
    EXPECT_EQ(st.lampIndex, 2);
    EXPECT_EQ(u.classification().name, "d65-fluorescent");
    EXPECT_EQ(st.illuminant.v, setup_.booth.lights[2].referenceSpectrum.v);
    EXPECT_EQ(st.emitterLuminanceCdM2, setup_.booth.lights[2].nominalLuminanceCdM2);
    // The same sample again changes nothing (sequence numbers).
    u.update(st, &f7_[static_cast<std::size_t>(confirm - 1)], nullptr, nullptr);
    EXPECT_EQ(st.lampIndex, 2);
}

TEST_F(SceneUpdaterTest, HysteresisIgnoresOneStraySpectrumAndSwitchesOnConfirmation)
{
    SceneUpdater u = make();
    pipeline::scene::SceneState st;
    std::uint32_t seq = 100;
    auto feed = [&](hal::SpectrumSample s) {
        s.sequence = ++seq;
        u.update(st, &s, nullptr, nullptr);
    };
    for (int i = 0; i < 3; ++i) {
        feed(f7_[static_cast<std::size_t>(i)]);
    }
    ASSERT_EQ(st.lampIndex, 2);
    // One tungsten spectrum between D65 ones does not switch (the single-threshold form did).
    feed(tungsten_[0]);
    EXPECT_EQ(st.lampIndex, 2);
    feed(f7_[3]);
    EXPECT_EQ(st.lampIndex, 2);
    // Tungsten for confirmSamples spectra in a row does.
    const int confirm = pipeline::spectral::LightClassifierParams{}.confirmSamples;
    for (int i = 1; i < confirm; ++i) {
        feed(tungsten_[static_cast<std::size_t>(i)]);
        EXPECT_EQ(st.lampIndex, 2);
    }
    feed(tungsten_[static_cast<std::size_t>(confirm)]);
    EXPECT_EQ(st.lampIndex, 0);
    EXPECT_EQ(st.illuminant.v, setup_.booth.lights[0].referenceSpectrum.v);
    EXPECT_EQ(st.emitterLuminanceCdM2, 2200.0);
}

TEST_F(SceneUpdaterTest, BadBoothsAreRefusedAndAnEmptyOneIsDirectSensorMode)
{
    SceneUpdaterSetup dark = setup_;
    dark.booth.lights[1].referenceSpectrum = pipeline::colour::Spectrum::constant(0.0);
    auto bad = SceneUpdater::create(dark);
    ASSERT_FALSE(bad);
    EXPECT_EQ(bad.error().message,
              "booth 'replica-booth-1': light classifier: stored light 'd50-fluorescent' has no "
              "energy");
    pipeline::spectral::LightClassifierParams params;
    params.releaseDistance = params.acceptDistance / 2.0;
    EXPECT_FALSE(SceneUpdater::create(setup_, params));

    SceneUpdaterSetup empty = setup_;
    empty.booth.lights.clear();
    auto u = SceneUpdater::create(empty);
    ASSERT_TRUE(u);
    pipeline::scene::SceneState st;
    for (const auto& s : f7_) {
        u->update(st, &s, nullptr, nullptr);
        EXPECT_EQ(st.lampIndex, -1);
    }
    EXPECT_GT(st.illuminant[20], 0.0);
}

TEST_F(SceneUpdaterTest, SaturatedSpectrumKeepsTheLastLight)
{
    SceneUpdater u = make();
    pipeline::scene::SceneState st;
    for (int i = 0; i < 3; ++i) {
        u.update(st, &f7_[static_cast<std::size_t>(i)], nullptr, nullptr);
    }
    ASSERT_EQ(st.lampIndex, 2);
    hal::SpectrumSample saturated = f7_[3];
    saturated.saturated = true;
    saturated.counts.assign(saturated.counts.size(), 65535);
    u.update(st, &saturated, nullptr, nullptr);
    EXPECT_EQ(st.lampIndex, 2);
    EXPECT_EQ(u.rejectedSpectra(), 1u);
}

TEST_F(SceneUpdaterTest, EyeMovesIntoTheBoothFrameAndHoldsThroughNaNAndLostTracking)
{
    SceneUpdater u = make();
    pipeline::scene::SceneState st;
    hal::PoseSample p;
    p.sequence = 1;
    p.tracked = true;
    p.eyeTrackerM = {0.1, 0.05, 0.5};
    u.update(st, nullptr, &p, nullptr);
    // The fixed mounting: a translation by (0, 0.42, 0.05) m, exactly.
    const glm::dvec3 expected = p.eyeTrackerM + glm::dvec3(0.0, 0.42, 0.05);
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
    SceneUpdater u = make();
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
