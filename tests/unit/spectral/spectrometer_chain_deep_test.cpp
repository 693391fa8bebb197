// Tests of the deeper spectrometer chain: non-linearity inversion, boxcar smoothing and the
// auto-integration controller in a closed loop with a raw-count model.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include <pipeline/base/data_dir.h>
#include <pipeline/offline/spectral/classifier_study.h>
#include <pipeline/spectral/reference_sets.h>
#include <pipeline/spectral/spectrometer_chain.h>

#include <gtest/gtest.h>

namespace replica::pipeline::spectral {
namespace {

constexpr int kPixels = 2048;
constexpr std::array<double, 4> kCoeffs{339.2, 0.3797, -1.62e-5, -1.3e-10};

double pixelNm(int p)
{
    const double x = p;
    return kCoeffs[0] + x * (kCoeffs[1] + x * (kCoeffs[2] + x * kCoeffs[3]));
}

SpectrometerCalibration flatCalibration()
{
    SpectrometerCalibration cal;
    for (double nm = 300.0; nm <= 1100.0; nm += 10.0) {
        cal.wavelengthNm.push_back(nm);
        cal.responsivity.push_back(1.0);
    }
    return cal;
}

// Counts of a smooth test SPD (a slope plus a bump) at 'countsPerUnit' for 1 s, with dark 1500 and
// the compressive response m = t / (1 - k t); optional alternating +-noise on every pixel.
std::vector<std::uint16_t> rawCounts(double countsPerUnit, double k, double zigzag)
{
    std::vector<std::uint16_t> c(kPixels);
    for (int p = 0; p < kPixels; ++p) {
        double t = 0.0;
        if (p > 21) {
            const double nm = pixelNm(p);
            t = countsPerUnit *
                (0.5 + nm / 1000.0 + std::exp(-0.5 * std::pow((nm - 550.0) / 40.0, 2)));
        }
        const double m = t / (1.0 - k * t) + (p > 21 ? zigzag * (p % 2 == 0 ? 1.0 : -1.0) : 0.0);
        c[static_cast<std::size_t>(p)] =
                static_cast<std::uint16_t>(std::clamp(std::round(1500.0 + m), 0.0, 65535.0));
    }
    return c;
}

Spectrum truth()
{
    Spectrum s;
    for (std::size_t i = 0; i < colour::kBands; ++i) {
        const double nm = colour::bandCentreNm(i);
        s[i] = 0.5 + nm / 1000.0 + std::exp(-0.5 * std::pow((nm - 550.0) / 40.0, 2));
    }
    return s;
}

TEST(SpectrometerChain, NonLinearityCorrectionRecoversTheLinearShape)
{
    constexpr double kK = -2.0e-6;
    const auto counts = rawCounts(20000.0, kK, 0.0);
    RawSpectrum raw{counts, 1'000'000, kCoeffs, {1.0, kK, 0, 0, 0, 0, 0, 0}};
    auto corrected = countsToSpectrum(raw, flatCalibration());
    RawSpectrum uncorrectedRaw{counts, 1'000'000, kCoeffs, {1.0, 0, 0, 0, 0, 0, 0, 0}};
    auto uncorrected = countsToSpectrum(uncorrectedRaw, flatCalibration());
    ASSERT_TRUE(corrected && uncorrected);
    // With the EEPROM polynomial the shape is the linear one (to count rounding and band
    // integration); without it the compression of the bright bump shows.
    const double good = spectralShapeDistance(*corrected, truth());
    const double bad = spectralShapeDistance(*uncorrected, truth());
    EXPECT_GT(bad, 0.01);
    EXPECT_LT(good, bad / 5.0);
}

TEST(SpectrometerChain, BoxcarKeepsBandValuesAndZeroWidthIsTheOriginalChain)
{
    // The 10 nm band integration already averages ~26 pixels, so pixel noise (here +-300 counts
    // alternating) is gone from the bands with or without the boxcar; the boxcar must not bias
    // them.
    const auto counts = rawCounts(15000.0, 0.0, 300.0);
    RawSpectrum raw{counts, 1'000'000, kCoeffs, {1.0, 0, 0, 0, 0, 0, 0, 0}};
    auto plain = countsToSpectrum(raw, flatCalibration());
    auto zero = countsToSpectrum(raw, flatCalibration(), ChainOptions{0});
    auto smooth = countsToSpectrum(raw, flatCalibration(), ChainOptions{5});
    ASSERT_TRUE(plain && zero && smooth);
    EXPECT_EQ(plain->v, zero->v);
    EXPECT_LT(spectralShapeDistance(*plain, truth()), 0.003);
    EXPECT_LT(spectralShapeDistance(*smooth, truth()), 0.003);
    EXPECT_LT(spectralShapeDistance(*smooth, *plain), 0.002);
    EXPECT_FALSE(countsToSpectrum(raw, flatCalibration(), ChainOptions{-1}));
}

TEST(AutoIntegration, ConvergesBelowSaturationFromEitherSide)
{
    // Closed loop: counts above dark grow with integration time; the brightest pixel must settle
    // within the tolerance band around 75 % of full scale, never staying saturated.
    const AutoIntegrationParams params;
    for (double countsPerSecond : {2.0e3, 4.0e5, 5.0e7}) {
        std::uint32_t us = 100'000;
        bool settled = false;
        for (int step = 0; step < 12; ++step) {
            const double scale = countsPerSecond * us * 1e-6 / 2.0; // truth() peaks near 2
            const auto counts = rawCounts(scale, 0.0, 0.0);
            const auto d = nextIntegrationTime(counts, 1500.0, us, params);
            if (!d.changed && !d.saturated) {
                const double peak = *std::max_element(counts.begin(), counts.end());
                EXPECT_LT(peak, params.saturationCounts) << countsPerSecond;
                EXPECT_NEAR(peak - 1500.0, 0.75 * 65535.0 - 1500.0,
                            params.toleranceFraction * (0.75 * 65535.0 - 1500.0) + 2.0)
                        << countsPerSecond;
                settled = true;
                break;
            }
            us = d.integrationTimeUs;
        }
        EXPECT_TRUE(settled) << countsPerSecond;
    }
}

TEST(AutoIntegration, SaturationCutsHardAndLimitsHold)
{
    std::vector<std::uint16_t> counts(kPixels, 1500);
    counts[900] = 65535;
    auto d = nextIntegrationTime(counts, 1500.0, 400'000);
    EXPECT_TRUE(d.saturated);
    EXPECT_EQ(d.integrationTimeUs, 100'000u);
    // Clamped at the hardware minimum, in 1 ms steps.
    d = nextIntegrationTime(counts, 1500.0, 2'000);
    EXPECT_EQ(d.integrationTimeUs, 1'000u);
    // Darkness: doubles, not a jump to 65 s.
    std::vector<std::uint16_t> dark(kPixels, 1500);
    d = nextIntegrationTime(dark, 1500.0, 100'000);
    EXPECT_EQ(d.integrationTimeUs, 200'000u);
    d = nextIntegrationTime(dark, 1500.0, 60'000'000);
    EXPECT_EQ(d.integrationTimeUs, 65'000'000u);
}

} // namespace
} // namespace replica::pipeline::spectral
