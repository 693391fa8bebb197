// The per-light channel-to-XYZ matrix: exact for reflectances inside the basis span.
#include <pipeline/base/data_dir.h>
#include <pipeline/colour/channel_basis.h>
#include <pipeline/colour/spectral_table.h>

#include <gtest/gtest.h>

namespace replica::pipeline::colour {
namespace {

TEST(ChannelBasis, ExactForReflectanceInTheSpanUnderSpikyLight)
{
    auto obs = loadCie1931(dataDir());
    auto t = loadSpectralCsv(dataDir() / "spectra" / "cie_illuminants_F1_F12_5nm_380_780.csv");
    ASSERT_TRUE(obs && t);
    const Spectrum light = *t->spectrum("F11", GridSampling::BandAverage);
    const ChannelBasis basis = boxBasis();
    // A reflectance that is constant in each box band lies in the box basis' span.
    Spectrum r;
    for (std::size_t i = 0; i < kBands; ++i) {
        r[i] = 0.1 + 0.13 * static_cast<double>(std::min<std::size_t>(i / 6, 5));
    }
    const ChannelCoeffs c = projectReflectance(basis, r);
    const ChannelToXyz m = channelToXyz(basis, *obs, light);
    Xyz approx{0.0};
    for (std::size_t k = 0; k < kChannels; ++k) {
        approx += c[k] * m[k];
    }
    // Reference: the full 36-band sum with the light scaled to Y = 1.
    const Xyz exact = spectrumToXyz(*obs, light * r) / spectrumToXyz(*obs, light).y;
    EXPECT_NEAR(approx.x, exact.x, 1e-12);
    EXPECT_NEAR(approx.y, exact.y, 1e-12);
    EXPECT_NEAR(approx.z, exact.z, 1e-12);
}

TEST(ChannelBasis, PerfectWhiteHasUnitLuminanceAndDarkLightGivesZero)
{
    auto obs = loadCie1931(dataDir());
    ASSERT_TRUE(obs);
    const ChannelBasis basis = boxBasis();
    const ChannelCoeffs white = projectReflectance(basis, Spectrum::constant(1.0));
    const ChannelToXyz m = channelToXyz(basis, *obs, Spectrum::constant(3.0));
    double y = 0.0;
    for (std::size_t k = 0; k < kChannels; ++k) {
        EXPECT_DOUBLE_EQ(white[k], 1.0);
        y += m[k].y;
    }
    EXPECT_NEAR(y, 1.0, 1e-12);
    const ChannelToXyz dark = channelToXyz(basis, *obs, Spectrum::constant(0.0));
    for (const auto& v : dark) {
        EXPECT_EQ(v, Xyz(0.0));
    }
}

} // namespace
} // namespace replica::pipeline::colour
