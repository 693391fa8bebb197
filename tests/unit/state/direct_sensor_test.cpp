// Direct-sensor mode (the paper's mode 1): forced by the run's light "direct" or reached when the
// classifier matches no lamp, it renders the calibrated reading on the booth's uniform emitter at
// the sensed level, L = directCdM2PerY * Y(reading), not at the booth's mean luminance.
#include <algorithm>
#include <cmath>
#include <span>
#include <vector>

#include <state/light_estimator.h>

#include <hal/sim/sim_devices.h>
#include <pipeline/base/data_dir.h>
#include <pipeline/colour/spectral_table.h>
#include <pipeline/colour/xyz.h>
#include <pipeline/spectral/direct_level.h>
#include <pipeline/spectral/spectrometer_chain.h>
#include <platform/appliance.h>

#include <gtest/gtest.h>

#include "../support/shipped_light.h"

namespace replica::state {
namespace {

class DirectSensorTest : public ::testing::Test
{
protected:
    void SetUp() override
    {
        setup_ = tests::shippedEstimatorSetup().light;
        auto observer = pipeline::colour::loadCie1931(dataDir());
        ASSERT_TRUE(observer) << observer.error().message;
        setup_.observer = *observer;
        auto f = pipeline::colour::loadSpectralCsv(dataDir() / "spectra" /
                                                   "cie_illuminants_F1_F12_5nm_380_780.csv");
        ASSERT_TRUE(f) << f.error().message;
        auto power = f->values("F7");
        ASSERT_TRUE(power) << power.error().message;
        hal::sim::ScenarioParams scenario;
        scenario.lampCount = 1;
        hal::sim::SimSpectrometerParams p;
        p.lamps = {hal::sim::SimLamp{"F7", f->wavelengthNm, *power}};
        p.responsivityNm = setup_.calibration.wavelengthNm;
        p.responsivity = setup_.calibration.responsivity;
        hal::sim::makeSimSpectrometer(scenario, p)->poll(1'200'000'000, f7_);
        ASSERT_EQ(f7_.size(), 6u);
    }

    // The reading's Y through the chain the estimator runs (LiveChainOptions::none(): one
    // spectrum, countsToSpectrum), computed here on its own.
    double readingY(const hal::SpectrumSample& s) const
    {
        pipeline::spectral::RawSpectrum raw{s.counts, s.integrationTimeUs, s.wavelengthCoeffs,
                                            s.nonlinearityCoeffs};
        auto spd = pipeline::spectral::countsToSpectrum(raw, setup_.calibration);
        EXPECT_TRUE(spd) << spd.error().message;
        return spd ? pipeline::colour::spectrumToXyz(setup_.observer, *spd).y : 0.0;
    }

    // The simulated instrument's readings of the shipped tungsten lamp (CIE A) over 'ns'.
    std::vector<hal::SpectrumSample> simTungsten(std::int64_t ns) const
    {
        std::vector<hal::SpectrumSample> out;
        auto a = pipeline::colour::loadSpectralCsv(dataDir() / "spectra" /
                                                   "cie_illuminants_A_D50_D65_5nm_300_780.csv");
        EXPECT_TRUE(a) << a.error().message;
        if (!a) {
            return out;
        }
        auto power = a->values("A");
        EXPECT_TRUE(power) << power.error().message;
        if (!power) {
            return out;
        }
        hal::sim::ScenarioParams scenario;
        scenario.lampCount = 1;
        hal::sim::SimSpectrometerParams p;
        p.lamps = {hal::sim::SimLamp{"A", a->wavelengthNm, *power}};
        p.responsivityNm = setup_.calibration.wavelengthNm;
        p.responsivity = setup_.calibration.responsivity;
        hal::sim::makeSimSpectrometer(scenario, p)->poll(ns, out);
        return out;
    }

    pipeline::scene::SceneState feed(LightEstimator& e, const hal::SpectrumSample& s) const
    {
        pipeline::scene::SceneState st;
        e.update(&s, nullptr);
        e.write(st);
        return st;
    }

    LightEstimator make() const
    {
        auto e = LightEstimator::create(setup_);
        EXPECT_TRUE(e) << e.error().message;
        return std::move(*e);
    }

    // A copy of 's' with a linear detector, dark pixels at exactly 'dark' and every signal count
    // (above dark) halved, then times 'factor' (1 or 2): two readings of one light, one twice the
    // other, count for count.
    static hal::SpectrumSample scaled(hal::SpectrumSample s, int factor, std::uint32_t sequence)
    {
        constexpr int dark = 1500;
        s.sequence = sequence;
        s.nonlinearityCoeffs = {1.0, 0, 0, 0, 0, 0, 0, 0};
        for (std::size_t p = 0; p < s.counts.size(); ++p) {
            const bool darkPixel = p >= 6 && p <= 20;
            const int signal = darkPixel ? 0 : std::max(int(s.counts[p]) - dark, 0) / 2;
            s.counts[p] = static_cast<std::uint16_t>(dark + factor * signal);
        }
        return s;
    }

    LightEstimatorSetup setup_;
    std::vector<hal::SpectrumSample> f7_;
};

TEST_F(DirectSensorTest, TheLevelFollowsTheReadingInClosedForm)
{
    setup_.forceDirect = true;
    setup_.directCdM2PerY = 0.37;
    LightEstimator e = make();
    for (const auto& s : f7_) {
        const auto st = feed(e, s);
        // Forced: never the classified lamp, although these are the D65 simulator's spectra.
        EXPECT_EQ(st.lampIndex, -1);
        const double y = readingY(s);
        ASSERT_GT(y, 0.0);
        EXPECT_NEAR(st.emitterLuminanceCdM2, 0.37 * y, 1e-12 * 0.37 * y);
        // The closed form is the library's too.
        EXPECT_EQ(st.emitterLuminanceCdM2, directLuminance(setup_, st.illuminant));
    }
}

TEST_F(DirectSensorTest, TwiceTheLightRendersTwiceTheLuminance)
{
    setup_.forceDirect = true;
    setup_.directCdM2PerY = 1.0;
    LightEstimator e = make();
    const auto once = feed(e, scaled(f7_[0], 1, 10));
    const auto twice = feed(e, scaled(f7_[0], 2, 11));
    ASSERT_GT(once.emitterLuminanceCdM2, 0.0);
    EXPECT_NEAR(twice.emitterLuminanceCdM2 / once.emitterLuminanceCdM2, 2.0, 1e-12);
    EXPECT_TRUE(twice.lightChanged); // another level is another light
    // The shape is the same light: the spectrum is twice the other, band for band.
    for (std::size_t b = 0; b < pipeline::colour::kBands; ++b) {
        EXPECT_NEAR(twice.illuminant[b], 2.0 * once.illuminant[b],
                    1e-9 * std::max(1.0, twice.illuminant[b]));
    }
}

TEST_F(DirectSensorTest, AutoFallsBackToTheSensedLevelAndThenShowsTheLamp)
{
    setup_.directCdM2PerY = 0.5; // auto: the classifier decides
    LightEstimator e = make();
    const int confirm = pipeline::spectral::LightClassifierParams{}.confirmSamples;
    for (int i = 0; i < confirm - 1; ++i) {
        const auto st = feed(e, f7_[static_cast<std::size_t>(i)]);
        EXPECT_EQ(st.lampIndex, -1);
        EXPECT_NEAR(st.emitterLuminanceCdM2, 0.5 * readingY(f7_[static_cast<std::size_t>(i)]),
                    1e-9 * st.emitterLuminanceCdM2);
    }
    const auto st = feed(e, f7_[static_cast<std::size_t>(confirm - 1)]);
    EXPECT_EQ(st.lampIndex, 2);
    EXPECT_EQ(st.emitterLuminanceCdM2, setup_.booth.lights[2].nominalLuminanceCdM2);
}

TEST_F(DirectSensorTest, ForcedModeDoesNotShowTheLampSelector)
{
    setup_.forceDirect = true;
    setup_.directCdM2PerY = 1.0;
    LightEstimator e = make();
    feed(e, f7_[0]);
    hal::LampSample sel;
    sel.sequence = 1;
    sel.lamp = 0;
    sel.lineCount = 3;
    sel.lineLevels = 1;
    e.update(nullptr, &sel);
    pipeline::scene::SceneState st;
    e.write(st);
    EXPECT_EQ(st.lampIndex, -1);
    EXPECT_NEAR(st.emitterLuminanceCdM2, readingY(f7_[0]), 1e-9 * st.emitterLuminanceCdM2);
}

TEST_F(DirectSensorTest, WithoutAScaleTheLevelIsTheBoothsMeanAsRecordingsMadeBefore)
{
    setup_.forceDirect = true;
    setup_.directCdM2PerY = 0.0;
    LightEstimator e = make();
    const auto st = feed(e, f7_[0]);
    EXPECT_DOUBLE_EQ(st.emitterLuminanceCdM2, (2200.0 + 2600.0 + 2600.0) / 3.0);
}

TEST_F(DirectSensorTest, TheDefaultScaleRendersTheSimulatedTungstenReadingAtItsNominalLuminance)
{
    // platform::kDefaultDirectCdM2PerY is the simulated instrument's calibration: its readings
    // of the shipped tungsten lamp (CIE A) come out at that lamp's 2200 cd/m^2, within the noise.
    const auto tungsten = simTungsten(1'200'000'000);
    ASSERT_EQ(tungsten.size(), 6u);
    setup_.forceDirect = true;
    setup_.directCdM2PerY = platform::kDefaultDirectCdM2PerY;
    LightEstimator e = make();
    double sum = 0.0;
    for (const auto& s : tungsten) {
        sum += feed(e, s).emitterLuminanceCdM2;
    }
    const double mean = sum / static_cast<double>(tungsten.size());
    EXPECT_NEAR(mean, setup_.booth.lights[0].nominalLuminanceCdM2, 0.005 * 2200.0);
    // The simulated D65 lamp reads at its peak-normalised level, about 1420 cd/m^2.
    sum = 0.0;
    for (const auto& s : f7_) {
        sum += readingY(s) * platform::kDefaultDirectCdM2PerY;
    }
    EXPECT_NEAR(sum / static_cast<double>(f7_.size()), 1420.0, 10.0);
}

// 'replica calibrate spectrometer --luminance-cdm2': from readings of one steady lamp and that
// lamp's metered luminance, the level at which the kiosk's own estimator (its live chain, the
// corrections on) renders that lamp at the metered luminance, whatever the instrument's scale.
TEST_F(DirectSensorTest, TheCalibratedLevelRendersTheMeteredLampAtItsLuminance)
{
    const auto tungsten = simTungsten(2'400'000'000);
    ASSERT_GE(tungsten.size(), 10u);
    // A lamp switch before it: three F7 readings, which the longest steady run leaves out.
    std::vector<hal::SpectrumSample> recorded(f7_.begin(), f7_.begin() + 3);
    recorded.insert(recorded.end(), tungsten.begin(), tungsten.end());
    std::vector<pipeline::spectral::RawSpectrum> raw;
    for (const auto& s : recorded) {
        raw.push_back({s.counts, s.integrationTimeUs, s.wavelengthCoeffs, s.nonlinearityCoeffs});
    }
    const pipeline::spectral::InstrumentCalibration instrument; // the data sheet's
    for (const double metered : {2200.0, 350.0}) {
        auto level = pipeline::spectral::calibrateDirectLevel(raw, setup_.calibration, instrument,
                                                              setup_.observer, metered);
        ASSERT_TRUE(level) << level.error().message;
        EXPECT_EQ(level->spectra, static_cast<int>(tungsten.size()));
        EXPECT_LT(level->spreadFraction, 0.05);
        // The kiosk's estimator with its default chain and that level.
        setup_.forceDirect = true;
        setup_.chain = pipeline::spectral::LiveChainOptions{};
        setup_.instrument = instrument;
        setup_.directCdM2PerY = level->cdm2PerY;
        LightEstimator e = make();
        double sum = 0.0;
        for (const auto& s : tungsten) {
            sum += feed(e, s).emitterLuminanceCdM2;
        }
        EXPECT_NEAR(sum / static_cast<double>(tungsten.size()), metered, 0.005 * metered);
        if (metered == 2200.0) {
            // The simulated instrument's own figure, found with the bare chain, is within the
            // stray light's share of this one.
            EXPECT_NEAR(level->cdm2PerY, platform::kDefaultDirectCdM2PerY,
                        0.02 * platform::kDefaultDirectCdM2PerY);
        }
    }
    // Refused: too few steady readings, no light, a luminance that is not a positive number.
    EXPECT_FALSE(pipeline::spectral::calibrateDirectLevel(
            std::span(raw).first(4), setup_.calibration, instrument, setup_.observer, 2200.0));
    EXPECT_FALSE(pipeline::spectral::calibrateDirectLevel(raw, setup_.calibration, instrument,
                                                          setup_.observer, -1.0));
    EXPECT_FALSE(pipeline::spectral::calibrateDirectLevel(raw, setup_.calibration, instrument,
                                                          setup_.observer, std::nan("")));
}

} // namespace
} // namespace replica::state
