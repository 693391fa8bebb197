// Sample-to-scene conversion: lamp classification, eye in the booth frame, tilt, and holding the
// last good value when a sample is unusable (NaN pose, lost tracking, undefined tilt, saturated
// spectrum).
#include <algorithm>
#include <cmath>
#include <limits>

#include <nlohmann/json.hpp>
#include <state/scene_estimator.h>

#include <hal/sim/sim_devices.h>
#include <pipeline/base/data_dir.h>
#include <pipeline/colour/spectral_table.h>
#include <pipeline/scene/booth.h>

#include <gtest/gtest.h>

#include "../support/shipped_light.h"

namespace replica::state {
namespace {

class SceneEstimatorTest : public ::testing::Test
{
protected:
    void SetUp() override
    {
        setup_ = tests::shippedEstimatorSetup();
        const auto& cal = setup_.light.calibration;
        // Raw counts of the D65 simulator (lamp 2) and of tungsten (lamp 0) from the simulated
        // spectrometer, six of each (1.2 s at five spectra a second).
        auto f = pipeline::colour::loadSpectralCsv(dataDir() / "spectra" /
                                                   "cie_illuminants_F1_F12_5nm_380_780.csv");
        auto a = pipeline::colour::loadSpectralCsv(dataDir() / "spectra" /
                                                   "cie_illuminants_A_D50_D65_5nm_300_780.csv");
        ASSERT_TRUE(f);
        ASSERT_TRUE(a);
        f7_ = sense(*f, "F7", cal);
        tungsten_ = sense(*a, "A", cal);
        ASSERT_EQ(f7_.size(), 6u);
        ASSERT_EQ(tungsten_.size(), 6u);
    }

    static std::vector<hal::SpectrumSample>
    sense(const pipeline::colour::SpectralTable& table,
          const std::string& column,
          const pipeline::spectral::SpectrometerCalibration& cal)
    {
        auto power = table.values(column);
        EXPECT_TRUE(power) << power.error().message;
        hal::sim::SimLamp lamp{column, table.wavelengthNm, power ? *power : std::vector<double>{}};
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

    SceneEstimator make() const
    {
        auto u = SceneEstimator::create(setup_);
        EXPECT_TRUE(u) << u.error().message;
        return std::move(*u);
    }

    SceneEstimatorSetup setup_;
    std::vector<hal::SpectrumSample> f7_;
    std::vector<hal::SpectrumSample> tungsten_;
};

TEST_F(SceneEstimatorTest, ClassifiesTheLampAndUsesItsStoredSpectrumAndLuminance)
{
    SceneEstimator u = make();
    pipeline::scene::SceneState st;
    const int confirm = pipeline::spectral::LightClassifierParams{}.confirmSamples;
    ASSERT_GE(confirm, 2);
    // Until the lamp has won confirmSamples spectra in a row: direct-sensor mode, the sensed
    // shape at the booth's mean luminance.
    for (int i = 0; i < confirm - 1; ++i) {
        u.update(st, &f7_[static_cast<std::size_t>(i)], nullptr, nullptr);
        EXPECT_EQ(st.lampIndex, -1);
        EXPECT_EQ(u.classification().name, "unknown");
        EXPECT_NE(st.illuminant.v, setup_.light.booth.lights[2].referenceSpectrum.v);
        EXPECT_GT(st.illuminant[20], 0.0);
        EXPECT_DOUBLE_EQ(st.emitterLuminanceCdM2, (2200.0 + 2600.0 + 2600.0) / 3.0);
    }
    u.update(st, &f7_[static_cast<std::size_t>(confirm - 1)], nullptr, nullptr);
    EXPECT_EQ(st.lampIndex, 2);
    EXPECT_EQ(u.classification().name, "d65-fluorescent");
    EXPECT_EQ(st.illuminant.v, setup_.light.booth.lights[2].referenceSpectrum.v);
    EXPECT_EQ(st.emitterLuminanceCdM2, setup_.light.booth.lights[2].nominalLuminanceCdM2);
    // The same sample again changes nothing (sequence numbers).
    u.update(st, &f7_[static_cast<std::size_t>(confirm - 1)], nullptr, nullptr);
    EXPECT_EQ(st.lampIndex, 2);
}

TEST_F(SceneEstimatorTest, HysteresisIgnoresOneStraySpectrumAndSwitchesOnConfirmation)
{
    SceneEstimator u = make();
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
    EXPECT_EQ(st.illuminant.v, setup_.light.booth.lights[0].referenceSpectrum.v);
    EXPECT_EQ(st.emitterLuminanceCdM2, 2200.0);
}

TEST_F(SceneEstimatorTest, BadBoothsAreRefusedAndAnEmptyOneIsDirectSensorMode)
{
    SceneEstimatorSetup dark = setup_;
    dark.light.booth.lights[1].referenceSpectrum = pipeline::colour::Spectrum::constant(0.0);
    auto bad = SceneEstimator::create(dark);
    ASSERT_FALSE(bad);
    EXPECT_EQ(bad.error().message,
              "booth 'replica-booth-1': light classifier: stored light 'd50-fluorescent' has no "
              "energy");
    pipeline::spectral::LightClassifierParams params;
    params.releaseDistance = params.acceptDistance / 2.0;
    SceneEstimatorSetup disordered = setup_;
    disordered.light.classifier = params;
    EXPECT_FALSE(SceneEstimator::create(disordered));

    SceneEstimatorSetup empty = setup_;
    empty.light.booth.lights.clear();
    auto u = SceneEstimator::create(empty);
    ASSERT_TRUE(u);
    pipeline::scene::SceneState st;
    for (const auto& s : f7_) {
        u->update(st, &s, nullptr, nullptr);
        EXPECT_EQ(st.lampIndex, -1);
    }
    EXPECT_GT(st.illuminant[20], 0.0);
}

TEST_F(SceneEstimatorTest, SaturatedSpectrumKeepsTheLastLight)
{
    SceneEstimator u = make();
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

TEST_F(SceneEstimatorTest, EyeMovesIntoTheBoothFrameAndHoldsThroughNaNAndLostTracking)
{
    SceneEstimator u = make();
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

TEST_F(SceneEstimatorTest, TiltHoldsWhenGravityIsAlongTheHinge)
{
    SceneEstimator u = make();
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
} // namespace replica::state

namespace replica::state {
namespace {

// What the rotation fix rests on: an estimator restored from another's save() (through its JSON
// text) estimates every later frame bit for bit as the original does, here with the classifier
// half-way through confirming a new lamp and the tilt half-way through a sliced refresh; a fresh
// estimator fed the same later samples does not.
TEST_F(SceneEstimatorTest, ARestoredEstimatorContinuesBitForBit)
{
    setup_.tilt.cacheSlices = 3;
    SceneEstimator a = make();
    std::uint32_t seq = 0;
    pipeline::scene::SceneState sa;
    const auto tiltSample = [&](double t) {
        hal::AccelSample s;
        s.sequence = ++seq;
        s.gravity = {0.0, -9.80665 * std::cos(t), -9.80665 * std::sin(t)};
        return s;
    };
    const auto poseSample = [&](double x) {
        hal::PoseSample p;
        p.sequence = ++seq;
        p.tracked = true;
        p.eyeTrackerM = {x, 0.05, 0.5};
        return p;
    };
    const auto step = [&](SceneEstimator& e, pipeline::scene::SceneState& st, int i,
                          const hal::SpectrumSample* spectrum) {
        // Frame i's samples: the same for every estimator (sequence numbers from i).
        hal::AccelSample acc = tiltSample(0.30 + 0.002 * i);
        acc.sequence = static_cast<std::uint32_t>(1000 + i);
        hal::PoseSample pose = poseSample(0.01 * i);
        pose.sequence = static_cast<std::uint32_t>(2000 + i);
        st.frameIndex = static_cast<std::uint64_t>(i);
        e.update(st, spectrum, &pose, &acc);
    };
    std::vector<hal::SpectrumSample> spectra;
    for (std::size_t i = 0; i < 3; ++i) {
        spectra.push_back(f7_[i]);
    }
    for (std::size_t i = 0; i < 5; ++i) {
        spectra.push_back(tungsten_[i]);
    }
    for (std::size_t i = 0; i < spectra.size(); ++i) {
        spectra[i].sequence = static_cast<std::uint32_t>(3000 + i);
    }
    // Frame i sees spectrum i / 2.
    const auto spectrumAt = [&](int i) { return &spectra[static_cast<std::size_t>(i / 2)]; };
    const int saveAt = 8; // D65 confirmed; tungsten has won 2 of the 3 spectra it needs
    for (int i = 0; i <= saveAt; ++i) {
        step(a, sa, i, spectrumAt(i));
    }
    ASSERT_EQ(sa.lampIndex, 2);
    ASSERT_EQ(a.classification().name, "d65-fluorescent");
    const std::string text = a.save().dump();
    SceneEstimator b = make();
    ASSERT_TRUE(b.restore(nlohmann::json::parse(text)));
    EXPECT_EQ(b.save().dump(), text);
    SceneEstimator fresh = make();
    pipeline::scene::SceneState sb, sf;
    int freshDiffers = 0;
    bool refreshSeen = false, lampChangeSeen = false;
    for (int i = saveAt + 1; i < 16; ++i) {
        step(a, sa, i, spectrumAt(i));
        step(b, sb, i, spectrumAt(i));
        step(fresh, sf, i, spectrumAt(i));
        EXPECT_EQ(sb.lampIndex, sa.lampIndex) << i;
        EXPECT_EQ(sb.illuminant.v, sa.illuminant.v) << i;
        EXPECT_EQ(sb.emitterLuminanceCdM2, sa.emitterLuminanceCdM2) << i;
        EXPECT_EQ(sb.lightChanged, sa.lightChanged) << i;
        EXPECT_EQ(sb.encoding, sa.encoding) << i;
        EXPECT_EQ(sb.eyeBoothM, sa.eyeBoothM) << i;
        EXPECT_EQ(sb.tiltRad, sa.tiltRad) << i;
        EXPECT_EQ(sb.heldTiltRad, sa.heldTiltRad) << i;
        EXPECT_EQ(sb.diffuse, sa.diffuse) << i;
        refreshSeen = refreshSeen || sa.diffuse->band.has_value();
        lampChangeSeen = lampChangeSeen || (sa.lightChanged && sa.lampIndex == 0);
        freshDiffers += sf.lampIndex != sa.lampIndex || sf.diffuse != sa.diffuse ? 1 : 0;
    }
    EXPECT_TRUE(refreshSeen);    // the tilt moved on far enough to refresh in bands
    EXPECT_TRUE(lampChangeSeen); // tungsten confirmed after the restore
    EXPECT_GT(freshDiffers, 0);  // without the saved state the frames are not the same
}

TEST_F(SceneEstimatorTest, ARestoreOfAnotherVersionOrBoothIsRefusedWithOneLine)
{
    SceneEstimator a = make();
    pipeline::scene::SceneState st;
    a.update(st, &f7_[0], nullptr, nullptr);
    auto saved = a.save();
    SceneEstimator b = make();
    auto wrongVersion = saved;
    wrongVersion["version"] = 2;
    auto v = b.restore(wrongVersion);
    ASSERT_FALSE(v);
    EXPECT_EQ(v.error().message,
              "the saved estimator state is not version 1 (replay it with the build that made it)");
    auto wrongLamp = saved;
    wrongLamp["light"]["lamp"] = 7;
    auto l = b.restore(wrongLamp);
    ASSERT_FALSE(l);
    EXPECT_EQ(l.error().message, "light: lamp 7 is not one of the booth's 3 lamps");
    auto noEye = saved;
    noEye.erase("eye");
    EXPECT_FALSE(b.restore(noEye));
}

} // namespace
} // namespace replica::state

namespace replica::state {
namespace {

// What the estimators refuse, they say why (loop/refusal_log.h puts it in the log): a spectrum
// with an integration time no USB2000+ takes (1 us would read a lamp a thousand times too
// bright), a tilt reading far from 1 g, and poses no head can take (1e298 m away, a 0.5 m jump in
// 10 ms), each holding the last good value; a head that really moved is followed.
TEST_F(SceneEstimatorTest, RefusedSamplesHoldTheLastGoodValueAndSayWhy)
{
    SceneEstimator u = make();
    pipeline::scene::SceneState st;
    for (int i = 0; i < 3; ++i) {
        u.update(st, &f7_[static_cast<std::size_t>(i)], nullptr, nullptr);
    }
    ASSERT_EQ(st.lampIndex, 2);
    hal::SpectrumSample quick = tungsten_[3];
    quick.integrationTimeUs = 1;
    u.update(st, &quick, nullptr, nullptr);
    EXPECT_EQ(st.lampIndex, 2);
    EXPECT_EQ(u.rejectedSpectra(), 1u);
    EXPECT_NE(u.light().lastRefusal().find("integration time of 1 us"), std::string::npos)
            << u.light().lastRefusal();

    hal::AccelSample a;
    a.sequence = 1;
    a.gravity = {0.0, -9.80665 * std::cos(0.5), -9.80665 * std::sin(0.5)};
    u.update(st, nullptr, nullptr, &a);
    hal::AccelSample weak = a;
    weak.sequence = 2;
    weak.gravity *= 0.8; // a scale 20 % off: the direction is right, the reading is not 1 g
    u.update(st, nullptr, nullptr, &weak);
    EXPECT_NEAR(st.tiltRad, 0.5, 1e-12);
    EXPECT_NE(u.tilt().lastRefusal().find("(0.80 g)"), std::string::npos) << u.tilt().lastRefusal();

    hal::PoseSample p;
    p.sequence = 10;
    p.timestampNs = 1'000'000'000;
    p.tracked = true;
    p.eyeTrackerM = {0.0, 0.05, 0.5};
    u.update(st, nullptr, &p, nullptr);
    const glm::dvec3 good = st.eyeBoothM;
    const auto pose = [&](std::int64_t dtMs, glm::dvec3 e) {
        p.sequence++;
        p.timestampNs += dtMs * 1'000'000;
        p.eyeTrackerM = e;
        u.update(st, nullptr, &p, nullptr);
        return st.eyeBoothM;
    };
    EXPECT_EQ(pose(10, {1e298, 0.05, 0.5}), good);
    EXPECT_NE(u.eye().lastRefusal().find("from the booth's origin"), std::string::npos);
    EXPECT_EQ(pose(10, {0.5, 0.05, 0.5}), good); // 0.5 m in 20 ms: 25 m/s
    EXPECT_NE(u.eye().lastRefusal().find("moved 0.500 m in 20 ms"), std::string::npos)
            << u.eye().lastRefusal();
    EXPECT_EQ(u.eye().refusedPoses(), 2u);
    // Walking pace is followed; so is a jump once enough time has passed for a head to make it
    // (the tracker re-centred, another viewer).
    EXPECT_NE(pose(10, {0.01, 0.05, 0.5}), good);
    EXPECT_EQ(pose(10, {0.5, 0.05, 0.5}).x, 0.01); // 0.49 m in 10 ms: refused
    EXPECT_EQ(pose(200, {0.5, 0.05, 0.5}).x, 0.5); // in 210 ms: 2.3 m/s
    EXPECT_EQ(u.eye().refusedPoses(), 3u);
    hal::PoseSample lost = p;
    lost.sequence++;
    lost.tracked = false;
    u.update(st, nullptr, &lost, nullptr);
    EXPECT_FALSE(u.eye().viewerInView());
    EXPECT_EQ(u.eye().refusedPoses(), 3u) << "a viewer out of view is no refusal";
}

} // namespace
} // namespace replica::state

namespace replica::state {
namespace {

// A spectrum whose brightest pixel stands within ten times the detector's noise of the dark level
// (a dark room) says how much light there is, not its colour: the frame shows the colour it had
// (here the D65 lamp's spectrum), at the reading's level in direct-sensor mode, and the classifier
// is not asked; light again shows the lamp at once (the classifier still holds it).
TEST_F(SceneEstimatorTest, AReadingTooWeakForItsColourKeepsTheColourAtItsLevel)
{
    // The simulated instrument's direct-sensor level (platform::kDefaultDirectCdM2PerY): its
    // readings render at their lamp's luminance (direct_sensor_test.cpp).
    setup_.light.directCdM2PerY = 7.3451e-5;
    auto observer = pipeline::colour::loadCie1931(dataDir());
    ASSERT_TRUE(observer);
    setup_.light.observer = *observer;
    SceneEstimator u = make();
    pipeline::scene::SceneState st;
    for (int i = 0; i < 3; ++i) {
        u.update(st, &f7_[static_cast<std::size_t>(i)], nullptr, nullptr);
    }
    ASSERT_EQ(st.lampIndex, 2);
    const pipeline::colour::Spectrum lampSpd = st.illuminant;
    const double nominal = st.emitterLuminanceCdM2;
    // The same light at 1/400 of it (100 counts above dark at the peak) on a detector whose dark
    // pixels scatter by 20 counts (a fixed pattern of +-20 about the same mean): the peak within
    // ten times the noise.
    hal::SpectrumSample dim = f7_[3];
    const auto& cal = setup_.light.calibration;
    double dark = 0.0;
    for (int p = cal.darkPixelFirst; p <= cal.darkPixelLast; ++p) {
        dark += dim.counts[static_cast<std::size_t>(p)];
    }
    dark /= cal.darkPixelLast - cal.darkPixelFirst + 1;
    for (int p = cal.darkPixelFirst; p + 1 <= cal.darkPixelLast; p += 2) {
        dim.counts[static_cast<std::size_t>(p)] += 20;
        dim.counts[static_cast<std::size_t>(p + 1)] -= 20;
    }
    for (std::size_t p = static_cast<std::size_t>(cal.darkPixelLast) + 1; p < dim.counts.size();
         ++p) {
        dim.counts[p] =
                static_cast<std::uint16_t>(std::lround(dark + (dim.counts[p] - dark) / 400.0));
    }
    const auto level = pipeline::spectral::signalLevel(dim.counts, cal);
    ASSERT_LT(level.peakAboveDark, 120.0);
    ASSERT_GT(level.darkNoise, 15.0);
    u.update(st, &dim, nullptr, nullptr);
    EXPECT_EQ(st.lampIndex, -1);
    EXPECT_EQ(u.light().weakSpectra(), 1u);
    EXPECT_TRUE(u.light().showingWeak());
    // The lamp's colour: the same shape band for band.
    const double k = st.illuminant[20] / lampSpd[20];
    EXPECT_GT(k, 0.0);
    for (std::size_t i = 0; i < pipeline::colour::kBands; ++i) {
        EXPECT_NEAR(st.illuminant[i], k * lampSpd[i], 1e-12 * (1.0 + lampSpd[i])) << i;
    }
    // At the reading's level: about 1/400 of the lamp's (the rounding of the counts and
    // direct-sensor mode's own scale move it a little), neither the lamp's nor none.
    EXPECT_GT(st.emitterLuminanceCdM2, nominal / 1600.0);
    EXPECT_LT(st.emitterLuminanceCdM2, nominal / 100.0);
    u.update(st, &f7_[4], nullptr, nullptr);
    EXPECT_EQ(st.lampIndex, 2);
    EXPECT_FALSE(u.light().showingWeak());
}

} // namespace
} // namespace replica::state
