// The pixel-level spectrometer model (offline/spectral/sensed_light.h) and the chain's corrections
// for stray light and wavelength shift (spectral/spectrometer_chain.h), against closed forms and
// injected values.
#include <cmath>

#include <pipeline/base/data_dir.h>
#include <pipeline/colour/spectral_table.h>
#include <pipeline/colour/xyz.h>
#include <pipeline/offline/spectral/sensed_light.h>
#include <pipeline/spectral/light_classifier.h>
#include <pipeline/spectral/spectrometer_chain.h>

#include <gtest/gtest.h>

namespace replica::pipeline::spectral {
namespace {

colour::Observer observer()
{
    auto obs = colour::loadCie1931(dataDir());
    EXPECT_TRUE(obs) << obs.error().message;
    return *obs;
}

FineLight lamp(const std::string& file, const std::string& column)
{
    auto t = colour::loadSpectralCsv(dataDir() / "spectra" / file);
    EXPECT_TRUE(t) << t.error().message;
    auto fine = restoreLines(*t, column);
    EXPECT_TRUE(fine) << fine.error().message;
    return *fine;
}

FineLight f7()
{
    return lamp("cie_illuminants_F1_F12_5nm_380_780.csv", "F7");
}
FineLight illA()
{
    return lamp("cie_illuminants_A_D50_D65_5nm_300_780.csv", "A");
}

// Largest relative band error over 400-700 nm, both spectra at unit mean.
double worstBandError(const colour::Spectrum& a, const colour::Spectrum& b)
{
    double ma = 0.0;
    double mb = 0.0;
    for (std::size_t i = 0; i < colour::kBands; ++i) {
        ma += a[i];
        mb += b[i];
    }
    double worst = 0.0;
    for (std::size_t i = 2; i + 3 < colour::kBands; ++i) {
        worst = std::max(worst, std::abs(a[i] / ma - b[i] / mb) / (b[i] / mb));
    }
    return worst;
}

InstrumentImpairments opticsOnly()
{
    InstrumentImpairments i = idealInstrument();
    i.fwhmNm = 1.3;
    return i;
}

TEST(SensedLight, RestoresAMercuryLineFromItsFiveNanometreBin)
{
    // Flat 1 from 380 to 780 nm, the 435 nm sample raised by 4: one line of 4 x 5 nm = 20 at
    // 435.833 nm, the continuum flat again.
    std::string csv = "wavelength_nm,flat\n";
    for (int nm = 380; nm <= 780; nm += 5) {
        csv += std::to_string(nm) + "," + (nm == 435 ? "5" : "1") + "\n";
    }
    auto table = colour::parseSpectralCsv(csv, "flat.csv");
    ASSERT_TRUE(table) << table.error().message;
    auto fine = restoreLines(*table, "flat");
    ASSERT_TRUE(fine) << fine.error().message;
    ASSERT_EQ(fine->lines.size(), 1u);
    EXPECT_DOUBLE_EQ(fine->lines[0].first, 435.833);
    EXPECT_NEAR(fine->lines[0].second, 20.0, 1e-12);
    for (double v : fine->continuum) {
        EXPECT_DOUBLE_EQ(v, 1.0);
    }
    // On the working grid: 1 everywhere plus 20 x triangle(distance) / 10 nm in the two bands
    // either side of the line: 430 nm gets 2 (1 - 5.833 / 10), 440 nm gets 2 (1 - 4.167 / 10).
    auto grid = fineLightToWorkingGrid(*fine);
    ASSERT_TRUE(grid) << grid.error().message;
    EXPECT_NEAR((*grid)[5], 1.0 + 2.0 * (1.0 - 5.833 / 10.0), 1e-9);
    EXPECT_NEAR((*grid)[6], 1.0 + 2.0 * (1.0 - 4.167 / 10.0), 1e-9);
    EXPECT_NEAR((*grid)[4], 1.0, 1e-9);
    EXPECT_NEAR((*grid)[20], 1.0, 1e-9);
    // A smooth light keeps no line.
    EXPECT_TRUE(illA().lines.empty());
    EXPECT_EQ(f7().lines.size(), 3u);
    EXPECT_FALSE(restoreLines(*table, "nope").has_value());
}

TEST(SensedLight, AnUnimpairedInstrumentReturnsTheLight)
{
    // The pixel simulation and the chain against the fine light integrated directly: two routes
    // to the same bands.
    const auto obs = observer();
    for (const auto& [light, tolerance] : {std::pair{illA(), 1e-3}, std::pair{f7(), 5e-3}}) {
        auto real = fineLightToWorkingGrid(light);
        ASSERT_TRUE(real);
        auto s = senseLight(light, obs, opticsOnly(), {}, 7);
        ASSERT_TRUE(s) << s.error().message;
        EXPECT_LT(worstBandError(s->spd, *real), tolerance) << light.name;
        // Scaled to the real light's luminance.
        EXPECT_NEAR(colour::spectrumToXyz(obs, s->spd).y, colour::spectrumToXyz(obs, *real).y,
                    1e-9 * colour::spectrumToXyz(obs, *real).y);
        // Auto-integration left the peak within its +-15 % band around 75 % of full scale.
        EXPECT_GT(s->peakCounts, 0.60 * 65535.0);
        EXPECT_LT(s->peakCounts, 0.90 * 65535.0);
    }
    // With the line in one pixel (no optical blur) the 10 nm bands see it at the pixel's centre:
    // worse than with the 1.3 nm line-spread function, which the triangular band averages exactly.
    auto real = fineLightToWorkingGrid(f7());
    auto sharp = senseLight(f7(), obs, idealInstrument(), {}, 7);
    auto blurred = senseLight(f7(), obs, opticsOnly(), {}, 7);
    ASSERT_TRUE(real && sharp && blurred);
    EXPECT_GT(worstBandError(sharp->spd, *real), 2.0 * worstBandError(blurred->spd, *real));
}

TEST(SensedLight, FindsAnInjectedWavelengthErrorAgainstTheMercuryLines)
{
    const auto obs = observer();
    for (double injected : {-0.45, 0.3}) {
        InstrumentImpairments imp; // the data sheet's, noise included
        imp.wavelengthErrorNm = injected;
        SensingCorrections corr;
        corr.wavelengthLines = true;
        auto s = senseLight(f7(), obs, imp, corr, 11);
        ASSERT_TRUE(s) << s.error().message;
        ASSERT_TRUE(s->linesFound);
        EXPECT_NEAR(s->wavelengthFoundNm, injected, 0.05);
        // Under tungsten there is no line: nothing found, and the remembered shift is used.
        corr.rememberedOffsetNm = 0.25;
        auto a = senseLight(illA(), obs, imp, corr, 11);
        ASSERT_TRUE(a);
        EXPECT_FALSE(a->linesFound);
        EXPECT_DOUBLE_EQ(a->wavelengthFoundNm, 0.25);
    }
}

TEST(SensedLight, CalibrateSpectrometerFindsTheInstrumentsShiftFromTheMercuryLines)
{
    // 'replica calibrate spectrometer' on the data-sheet instrument (noise, stray light and the
    // residual non-linearity on) with a known error in its EEPROM polynomial: 30 scans of a
    // fluorescent lamp whose mercury lines are restored from the CIE table's 5 nm bins, in runs
    // of 10. Each run's lines give the shift; the median is within 0.05 nm of the truth and the
    // runs agree.
    for (double injected : {-0.45, 0.0, 0.3}) {
        InstrumentImpairments imp;
        imp.wavelengthErrorNm = injected;
        auto cal = calibrateShiftOnSimulatedInstrument(f7(), imp, 30, 10, 21);
        ASSERT_TRUE(cal) << cal.error().message;
        ASSERT_TRUE(cal->has_value()) << injected;
        EXPECT_NEAR((*cal)->offsetNm, injected, 0.05);
        EXPECT_EQ((*cal)->runs, 3);
        EXPECT_LT((*cal)->spreadNm, 0.1);
    }
    // Tungsten has no line to calibrate against: nothing is claimed.
    auto none = calibrateShiftOnSimulatedInstrument(illA(), InstrumentImpairments{}, 20, 10, 21);
    ASSERT_TRUE(none) << none.error().message;
    EXPECT_FALSE(none->has_value());
    EXPECT_FALSE(calibrateShiftOnSimulatedInstrument(f7(), InstrumentImpairments{}, 0, 10, 1));
}

TEST(SensedLight, StrayLightCorrectionRemovesTheCharacterisedLevel)
{
    // Noise off, 0.5 % stray light (ten times the data sheet's, to stand well above the floor):
    // every pixel gains 0.005 of the peak signal. Under tungsten the blue end carries a few per
    // cent of the peak, so the uncorrected blue bands are off by about 0.005 / (their share of the
    // peak).
    const auto obs = observer();
    InstrumentImpairments imp = opticsOnly();
    imp.strayFraction = 5e-3;
    auto real = fineLightToWorkingGrid(illA());
    auto raw = senseLight(illA(), obs, imp, {}, 3);
    SensingCorrections corr;
    corr.strayLight = true;
    auto fixed = senseLight(illA(), obs, imp, corr, 3);
    ASSERT_TRUE(real && raw && fixed);
    EXPECT_GT(worstBandError(raw->spd, *real), 0.02);
    EXPECT_LT(worstBandError(fixed->spd, *real), 2e-3);
}

TEST(SensedLight, IsReproducibleForASeed)
{
    const auto obs = observer();
    const InstrumentImpairments imp;
    auto a = senseLight(f7(), obs, imp, {}, 5);
    auto b = senseLight(f7(), obs, imp, {}, 5);
    auto c = senseLight(f7(), obs, imp, {}, 6);
    ASSERT_TRUE(a && b && c);
    double diff = 0.0;
    for (std::size_t i = 0; i < colour::kBands; ++i) {
        EXPECT_EQ(a->spd[i], b->spd[i]);
        diff += std::abs(a->spd[i] - c->spd[i]);
    }
    EXPECT_GT(diff, 0.0);
    EXPECT_EQ(drawWavelengthError(0.5, 9), drawWavelengthError(0.5, 9));
    EXPECT_LE(std::abs(drawWavelengthError(0.5, 9)), 0.5);
}

TEST(SpectrometerChain, WavelengthOffsetNeedsLines)
{
    // A flat spectrum has no peak: no offset is claimed.
    std::vector<std::uint16_t> counts(2048, 20000);
    for (int p = 6; p <= 21; ++p) {
        counts[static_cast<std::size_t>(p)] = 1500;
    }
    RawSpectrum raw;
    raw.counts = counts;
    raw.integrationTimeUs = 100000;
    raw.wavelengthCoeffs = {339.2, 0.3797, -1.62e-5, -1.3e-10};
    SpectrometerCalibration cal;
    cal.wavelengthNm = {300.0, 1200.0};
    cal.responsivity = {1.0, 1.0};
    EXPECT_FALSE(estimateWavelengthOffset(raw, cal, kMercuryLinesNm).has_value());
    ChainOptions bad;
    bad.strayLightFraction = 2.0; // out of [0, 1)
    EXPECT_FALSE(countsToSpectrum(raw, cal, bad).has_value());
}

TEST(SensedLight, ApplianceChainAveragesASteadyLightWholly)
{
    // The data-sheet instrument on lights the project never names (a narrow tri-band fluorescent,
    // an RGB LED, a phosphor LED): a steady light stays within the chain's steadiness, so every
    // one of the five spectra is averaged, and the shape comes closer to the real light than one
    // spectrum's.
    const auto obs = observer();
    for (const auto& light : {lamp("cie_illuminants_F1_F12_5nm_380_780.csv", "F12"),
                              lamp("cie_illuminants_LED_5nm_380_780.csv", "LED-RGB1"),
                              lamp("cie_illuminants_LED_5nm_380_780.csv", "LED-B3")}) {
        auto real = fineLightToWorkingGrid(light);
        ASSERT_TRUE(real);
        SensingCorrections one;
        one.applianceChain = true;
        one.rememberedOffsetNm = 0.0;
        SensingCorrections five = one;
        five.scansAveraged = five.chain.averageSpectra;
        auto a = senseLight(light, obs, InstrumentImpairments{}, one, 7);
        auto b = senseLight(light, obs, InstrumentImpairments{}, five, 7);
        ASSERT_TRUE(a && b);
        EXPECT_EQ(a->scansAveraged, 1) << light.name;
        EXPECT_EQ(b->scansAveraged, 5) << light.name;
        EXPECT_LT(spectralShapeDistance(b->spd, *real), spectralShapeDistance(a->spd, *real))
                << light.name;
    }
}

} // namespace
} // namespace replica::pipeline::spectral
