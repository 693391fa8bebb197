// The simulated USB2000+ and the signal chain together: raw counts of each booth lamp come back as
// the lamp's spectral shape, and the classifier names the lamp (or 'unknown' for a foreign light).
#include <hal/sim/sim_devices.h>
#include <pipeline/base/data_dir.h>
#include <pipeline/colour/spectral_table.h>
#include <pipeline/scene/booth.h>
#include <pipeline/spectral/light_classifier.h>
#include <pipeline/spectral/spectrometer_chain.h>

#include <gtest/gtest.h>

#include "../support/shipped_light.h"

namespace replica {
namespace {

using pipeline::colour::Spectrum;

// The shipped booth and the sim spectrometer's calibration.
state::LightEstimatorSetup load()
{
    return tests::shippedEstimatorSetup().light;
}

hal::sim::SimLamp rawLamp(const std::string& file, const std::string& column)
{
    auto t = pipeline::colour::loadSpectralCsv(dataDir() / "spectra" / file);
    EXPECT_TRUE(t);
    auto power = t->values(column);
    EXPECT_TRUE(power) << power.error().message;
    return {column, t->wavelengthNm, power ? *power : std::vector<double>{}};
}

// Spectra measured from a sim spectrometer that shows the given lamps in turn (2 s each).
std::vector<hal::SpectrumSample> measure(std::vector<hal::sim::SimLamp> lamps,
                                         const pipeline::spectral::SpectrometerCalibration& cal,
                                         std::int64_t untilNs)
{
    hal::sim::ScenarioParams scenario;
    scenario.lampCount = static_cast<int>(lamps.size());
    hal::sim::SimSpectrometerParams p;
    p.lamps = std::move(lamps);
    p.responsivityNm = cal.wavelengthNm;
    p.responsivity = cal.responsivity;
    auto sim = hal::sim::makeSimSpectrometer(scenario, p);
    std::vector<hal::SpectrumSample> out;
    sim->poll(untilNs, out);
    return out;
}

Spectrum convert(const hal::SpectrumSample& s,
                 const pipeline::spectral::SpectrometerCalibration& cal)
{
    auto spd = pipeline::spectral::countsToSpectrum(
            {s.counts, s.integrationTimeUs, s.wavelengthCoeffs, s.nonlinearityCoeffs}, cal);
    EXPECT_TRUE(spd) << spd.error().message;
    return *spd;
}

TEST(SimSpectrometer, FiveSpectraPerSecondWithSequenceAndCalibration)
{
    const auto b = load();
    auto spectra = measure({rawLamp("cie_illuminants_A_D50_D65_5nm_300_780.csv", "A")},
                           b.calibration, 1'000'000'000);
    ASSERT_EQ(spectra.size(), 5u); // available at 0.1, 0.3, 0.5, 0.7, 0.9 s
    for (std::size_t i = 0; i < spectra.size(); ++i) {
        EXPECT_EQ(spectra[i].sequence, i);
        EXPECT_EQ(spectra[i].counts.size(), 2048u);
        EXPECT_FALSE(spectra[i].saturated);
        EXPECT_EQ(spectra[i].timestampNs, static_cast<std::int64_t>(i) * 200'000'000 + 100'000'000);
    }
}

TEST(SignalChain, RecoversEachBoothLampShapeFromRawCounts)
{
    const auto b = load();
    std::vector<hal::sim::SimLamp> lamps = {
            rawLamp("cie_illuminants_A_D50_D65_5nm_300_780.csv", "A"),
            rawLamp("cie_illuminants_F1_F12_5nm_380_780.csv", "F8"),
            rawLamp("cie_illuminants_F1_F12_5nm_380_780.csv", "F7")};
    // One spectrum in the middle of each lamp's 2 s slot.
    auto spectra = measure(lamps, b.calibration, 6'000'000'000);
    for (int lamp = 0; lamp < 3; ++lamp) {
        const auto& s = spectra[static_cast<std::size_t>(lamp * 10 + 5)];
        const Spectrum sensed = convert(s, b.calibration);
        const double d = pipeline::spectral::LightClassifier::shapeDistance(
                sensed, b.booth.lights[static_cast<std::size_t>(lamp)].referenceSpectrum);
        // Noise and the pixel-to-band integration leave a small residual; another lamp is far away.
        EXPECT_LT(d, 0.03) << "lamp " << lamp;
        for (int other = 0; other < 3; ++other) {
            if (other != lamp) {
                EXPECT_GT(
                        pipeline::spectral::LightClassifier::shapeDistance(
                                sensed,
                                b.booth.lights[static_cast<std::size_t>(other)].referenceSpectrum),
                        0.15);
            }
        }
    }
}

TEST(LightClassifier, NamesBoothLampsAndRejectsAForeignLight)
{
    const auto b = load();
    std::vector<Spectrum> stored;
    for (const auto& l : b.booth.lights) {
        stored.push_back(l.referenceSpectrum);
    }
    pipeline::spectral::LightClassifier classifier(stored);
    std::vector<hal::sim::SimLamp> lamps = {
            rawLamp("cie_illuminants_A_D50_D65_5nm_300_780.csv", "A"),
            rawLamp("cie_illuminants_F1_F12_5nm_380_780.csv", "F8"),
            rawLamp("cie_illuminants_F1_F12_5nm_380_780.csv", "F7"),
            rawLamp("cie_illuminants_LED_5nm_380_780.csv", "LED-V1")};
    auto spectra = measure(lamps, b.calibration, 8'000'000'000);
    for (const auto& s : spectra) {
        // The lamp slot the spectrum was integrated in (2 s per lamp).
        const auto lamp = static_cast<int>(((s.timestampNs - 50'000'000) / 2'000'000'000) % 4);
        const int expected = lamp < 3 ? lamp : -1;
        EXPECT_EQ(classifier.classify(convert(s, b.calibration)), expected)
                << "t=" << s.timestampNs;
    }
}

TEST(SignalChain, RejectsMalformedRawSpectra)
{
    const auto b = load();
    std::vector<std::uint16_t> few(10, 100);
    auto r = pipeline::spectral::countsToSpectrum({few, 1000, {339, 0.38, 0, 0}, {1}},
                                                  b.calibration);
    EXPECT_FALSE(r);
    std::vector<std::uint16_t> counts(2048, 100);
    auto z = pipeline::spectral::countsToSpectrum({counts, 0, {339, 0.38, 0, 0}, {1}},
                                                  b.calibration);
    ASSERT_FALSE(z);
    EXPECT_NE(z.error().message.find("integration time"), std::string::npos);
    // A calibration that does not reach 730 nm cannot fill the working grid.
    auto narrow = pipeline::spectral::countsToSpectrum({counts, 1000, {339, 0.1, 0, 0}, {1}},
                                                       b.calibration);
    ASSERT_FALSE(narrow);
    EXPECT_NE(narrow.error().message.find("730"), std::string::npos);
}

} // namespace
} // namespace replica
