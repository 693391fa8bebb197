// Tests for working-grid resampling and CSV parsing.
#include <pipeline/base/data_dir.h>
#include <pipeline/colour/spectral_table.h>
#include <pipeline/colour/xyz.h>

#include <gtest/gtest.h>

namespace replica::pipeline::colour {
namespace {

TEST(Resample, FiveNanometreGridGivesTheCieTriangularFilter)
{
    // Compare with the published triangular 10 nm table: same rule, independent arithmetic.
    auto fine = loadSpectralCsv(dataDir() / "spectra" / "cie_illuminants_F1_F12_5nm_380_780.csv");
    auto tri =
            loadSpectralCsv(dataDir() / "spectra" / "cie_illuminants_10nm_380_730_triangular.csv");
    ASSERT_TRUE(fine) << fine.error().message;
    ASSERT_TRUE(tri) << tri.error().message;
    for (const char* name : {"F2", "F7", "F11"}) {
        auto a = fine->spectrum(name);
        auto b = tri->spectrum(name);
        ASSERT_TRUE(a && b);
        for (std::size_t i = 0; i < kBands; ++i) {
            EXPECT_NEAR((*a)[i], (*b)[i], 1e-9) << name << " band " << i;
        }
    }
}

TEST(Resample, TenNanometreGridIsIdentity)
{
    SampledSpectrum s;
    for (std::size_t i = 0; i < kBands; ++i) {
        s.wavelengthNm.push_back(bandCentreNm(i));
        s.value.push_back(static_cast<double>(i * i));
    }
    auto r = resampleToWorkingGrid(s, "test");
    ASSERT_TRUE(r);
    for (std::size_t i = 0; i < kBands; ++i) {
        EXPECT_DOUBLE_EQ((*r)[i], static_cast<double>(i * i));
    }
}

TEST(Resample, RejectsTooNarrowRange)
{
    SampledSpectrum s{{400.0, 500.0, 700.0}, {1.0, 1.0, 1.0}};
    auto r = resampleToWorkingGrid(s, "narrow.csv");
    ASSERT_FALSE(r);
    EXPECT_NE(r.error().message.find("narrow.csv"), std::string::npos);
    EXPECT_NE(r.error().message.find("380"), std::string::npos);
}

TEST(SpectralCsv, NamesFileAndLineOfBadCell)
{
    auto t = parseSpectralCsv("# c\nwavelength_nm,a\n380,1\n390,x\n", "bad.csv");
    ASSERT_FALSE(t);
    EXPECT_EQ(t.error().message, "bad.csv:4: column 'a' value 'x' is not a finite number");
}

TEST(SpectralCsv, RejectsNonIncreasingWavelength)
{
    auto t = parseSpectralCsv("wavelength_nm,a\n380,1\n380,2\n", "dup.csv");
    ASSERT_FALSE(t);
    EXPECT_NE(t.error().message.find("dup.csv:3"), std::string::npos);
}

TEST(SpectralCsv, RejectsMissingColumn)
{
    auto t = parseSpectralCsv("wavelength_nm,a,b\n380,1\n", "short.csv");
    ASSERT_FALSE(t);
    EXPECT_NE(t.error().message.find("short.csv:2"), std::string::npos);
}

TEST(Xyz, IlluminantAWhitePointOnWorkingGrid)
{
    // CIE A on the 36-band grid: x,y within 0.001 of the published 2-degree white (0.44757,
    // 0.40745).
    auto obs = loadCie1931(dataDir());
    auto t = loadSpectralCsv(dataDir() / "spectra" / "cie_illuminants_A_D50_D65_5nm_300_780.csv");
    ASSERT_TRUE(obs && t);
    auto a = t->spectrum("A");
    ASSERT_TRUE(a);
    const Xyz w = spectrumToXyz(*obs, *a);
    const double sum = w.x + w.y + w.z;
    EXPECT_NEAR(w.x / sum, 0.44757, 1e-3);
    EXPECT_NEAR(w.y / sum, 0.40745, 1e-3);
}

} // namespace
} // namespace replica::pipeline::colour
