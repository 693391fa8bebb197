// The live spectrometer chain (pipeline/spectral/live_chain.h): spectra of a steady lamp are
// averaged, a lamp switch starts a new average at once, so the classifier names the new lamp at
// the same spectrum as without averaging; the chain's state survives a save and restore.
#include <hal/sim/sim_devices.h>
#include <pipeline/colour/spectral_table.h>
#include <pipeline/spectral/light_classifier.h>
#include <pipeline/spectral/live_chain.h>

#include <gtest/gtest.h>

#include "../support/shipped_light.h"

namespace replica {
namespace {

namespace spectral = pipeline::spectral;

hal::sim::SimLamp simLamp(const std::string& file, const std::string& column)
{
    auto t = pipeline::colour::loadSpectralCsv(dataDir() / "spectra" / file);
    EXPECT_TRUE(t);
    auto power = t->values(column);
    EXPECT_TRUE(power) << power.error().message;
    return {column, t->wavelengthNm, power ? *power : std::vector<double>{}};
}

// 30 spectra at five a second: lamps A, F8, F7 in turn, 2 s each (the sim scenario's switch).
std::vector<hal::SpectrumSample> lampSwitches(const spectral::SpectrometerCalibration& cal)
{
    hal::sim::ScenarioParams scenario;
    scenario.lampCount = 3;
    hal::sim::SimSpectrometerParams p;
    p.lamps = {simLamp("cie_illuminants_A_D50_D65_5nm_300_780.csv", "A"),
               simLamp("cie_illuminants_F1_F12_5nm_380_780.csv", "F8"),
               simLamp("cie_illuminants_F1_F12_5nm_380_780.csv", "F7")};
    p.responsivityNm = cal.wavelengthNm;
    p.responsivity = cal.responsivity;
    auto sim = hal::sim::makeSimSpectrometer(scenario, p);
    std::vector<hal::SpectrumSample> out;
    sim->poll(6'000'000'000, out);
    return out;
}

spectral::RawSpectrum raw(const hal::SpectrumSample& s)
{
    return {s.counts, s.integrationTimeUs, s.wavelengthCoeffs, s.nonlinearityCoeffs};
}

TEST(LiveChain, LampSwitchShowsAtTheSameSpectrumAsWithoutAveraging)
{
    const auto setup = tests::shippedEstimatorSetup().light;
    const auto spectra = lampSwitches(setup.calibration);
    ASSERT_EQ(spectra.size(), 30u);
    std::vector<spectral::StoredLight> stored;
    for (const auto& l : setup.booth.lights) {
        stored.push_back({l.name, l.referenceSpectrum});
    }
    auto plainClassifier = spectral::LightClassifier::create(stored);
    auto liveClassifier = spectral::LightClassifier::create(stored);
    ASSERT_TRUE(plainClassifier && liveClassifier);
    spectral::LiveSpectrometerChain plain(setup.calibration, {},
                                          spectral::LiveChainOptions::none());
    spectral::LiveSpectrometerChain live(setup.calibration, {}, spectral::LiveChainOptions{});
    for (std::size_t i = 0; i < spectra.size(); ++i) {
        auto a = plain.add(raw(spectra[i]));
        auto b = live.add(raw(spectra[i]));
        ASSERT_TRUE(a && b);
        // Every decision the same, at the same spectrum: the switch is not delayed.
        EXPECT_EQ(plainClassifier->classify(*a), liveClassifier->classify(*b)) << "spectrum " << i;
        // Each lamp's first spectrum starts a new average; a steady lamp fills it.
        const std::size_t inSlot = i % 10;
        EXPECT_EQ(live.averaged(), static_cast<int>(std::min<std::size_t>(inSlot + 1, 5)))
                << "spectrum " << i;
        EXPECT_EQ(plain.averaged(), 0);
    }
    EXPECT_EQ(liveClassifier->current(), 2);
}

TEST(LiveChain, AveragingASteadyLampBringsItsShapeCloser)
{
    const auto setup = tests::shippedEstimatorSetup().light;
    const auto spectra = lampSwitches(setup.calibration);
    // Against the mean of many single spectra of the same lamp (the noise-free shape as this
    // chain sees it), over the last five spectra of each 2 s slot.
    for (int lamp = 0; lamp < 3; ++lamp) {
        spectral::LiveSpectrometerChain plain(setup.calibration, {},
                                              spectral::LiveChainOptions::none());
        spectral::LiveChainOptions all;
        all.averageSpectra = 10;
        spectral::LiveSpectrometerChain reference(setup.calibration, {}, all);
        spectral::LiveSpectrometerChain live(setup.calibration, {}, spectral::LiveChainOptions{});
        double single = 0.0;
        double averaged = 0.0;
        Expected<pipeline::colour::Spectrum> ref = makeError(ErrorCode::NotFound, "none");
        for (int i = 0; i < 10; ++i) {
            ref = reference.add(raw(spectra[static_cast<std::size_t>(lamp * 10 + i)]));
        }
        ASSERT_TRUE(ref);
        for (int i = 0; i < 10; ++i) {
            const auto& s = spectra[static_cast<std::size_t>(lamp * 10 + i)];
            auto a = plain.add(raw(s));
            auto b = live.add(raw(s));
            ASSERT_TRUE(a && b);
            if (i >= 5) {
                single += spectral::spectralShapeDistance(*a, *ref);
                averaged += spectral::spectralShapeDistance(*b, *ref);
            }
        }
        // Five spectra averaged: the noise about sqrt(5) smaller (with room for the draw).
        EXPECT_LT(averaged, 0.7 * single) << "lamp " << lamp;
    }
}

TEST(LiveChain, StateRestoresTheRunningAverage)
{
    const auto setup = tests::shippedEstimatorSetup().light;
    const auto spectra = lampSwitches(setup.calibration);
    spectral::LiveSpectrometerChain whole(setup.calibration, {}, spectral::LiveChainOptions{});
    for (int i = 0; i < 13; ++i) {
        ASSERT_TRUE(whole.add(raw(spectra[static_cast<std::size_t>(i)])));
    }
    spectral::LiveSpectrometerChain resumed(setup.calibration, {}, spectral::LiveChainOptions{});
    resumed.restore(whole.state());
    for (int i = 13; i < 18; ++i) {
        auto a = whole.add(raw(spectra[static_cast<std::size_t>(i)]));
        auto b = resumed.add(raw(spectra[static_cast<std::size_t>(i)]));
        ASSERT_TRUE(a && b);
        EXPECT_EQ(a->v, b->v) << "spectrum " << i;
        EXPECT_EQ(whole.averaged(), resumed.averaged());
    }
}

} // namespace
} // namespace replica

namespace replica {
namespace {

TEST(CalibrateSpectrometer, StrayLightIsWhatReachesBelowALongPassCutOn)
{
    // Dark 1500 counts; 40 000 counts above dark beyond 550 nm, 20 below it: 20 / 40 000.
    const spectral::SpectrometerCalibration cal;
    const std::array<double, 4> coeffs{339.2, 0.3797, -1.62e-5, -1.3e-10};
    std::vector<std::uint16_t> counts(2048, 1500);
    for (int p = cal.darkPixelLast + 1; p < 2048; ++p) {
        const double nm = coeffs[0] + p * (coeffs[1] + p * (coeffs[2] + p * coeffs[3]));
        counts[static_cast<std::size_t>(p)] = nm > 550.0 ? 41500 : 1520;
    }
    const std::vector<spectral::RawSpectrum> raws{
            {counts, 100'000, coeffs, {1.0, 0, 0, 0, 0, 0, 0, 0}}};
    const auto f = spectral::strayLightFromLongPass(raws, cal, 550.0);
    ASSERT_TRUE(f);
    EXPECT_NEAR(*f, 20.0 / 40000.0, 1e-9);
}

} // namespace
} // namespace replica
