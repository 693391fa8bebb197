// Tests for working-grid resampling and CSV parsing.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numeric>
#include <vector>

#include <pipeline/base/data_dir.h>
#include <pipeline/colour/ciede2000.h>
#include <pipeline/colour/cielab.h>
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
        auto a = fine->spectrum(name, GridSampling::BandAverage);
        auto b = tri->spectrum(name, GridSampling::BandAverage);
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
    auto r = resampleToWorkingGrid(s, "test", GridSampling::BandAverage);
    ASSERT_TRUE(r);
    for (std::size_t i = 0; i < kBands; ++i) {
        EXPECT_DOUBLE_EQ((*r)[i], static_cast<double>(i * i));
    }
}

// The band's triangle (10 nm half base) over the samples' linear interpolant, constant beyond the
// ends, by a fine midpoint sum: independent of the resampler's breakpoints and Simpson's rule.
double triangleByMidpoints(const SampledSpectrum& s, double centre)
{
    constexpr int kSteps = 200000;
    const double h = 20.0 / kSteps;
    double sum = 0.0;
    for (int k = 0; k < kSteps; ++k) {
        const double lambda = centre - 10.0 + (k + 0.5) * h;
        double v = s.value.front();
        if (lambda >= s.wavelengthNm.back()) {
            v = s.value.back();
        } else if (lambda > s.wavelengthNm.front()) {
            std::size_t i = 0;
            while (s.wavelengthNm[i + 1] <= lambda) {
                ++i;
            }
            const double t =
                    (lambda - s.wavelengthNm[i]) / (s.wavelengthNm[i + 1] - s.wavelengthNm[i]);
            v = s.value[i] + t * (s.value[i + 1] - s.value[i]);
        }
        sum += (1.0 - std::abs(lambda - centre) / 10.0) * v * h;
    }
    return sum / 10.0;
}

TEST(Resample, CoarseGridsAverageTheirInterpolantNotTheirEnds)
{
    // Grids coarser than the 10 nm bands: 20 nm offset by 5, 25 nm, and irregular 12-31 nm steps,
    // each from below 380 to past 730 nm, values of a smooth light with a line in it. Before, a
    // band with no sample within 10 nm of its centre took an end's value (300 or 780 nm).
    std::vector<std::vector<double>> grids(3);
    for (double w = 305.0; w <= 785.0; w += 20.0) {
        grids[0].push_back(w);
    }
    for (double w = 355.0; w <= 755.0; w += 25.0) {
        grids[1].push_back(w);
    }
    double w = 366.0;
    for (int k = 0; w <= 760.0; ++k) {
        grids[2].push_back(w);
        w += 12.0 + static_cast<double>((k * 7) % 20);
    }
    for (const auto& grid : grids) {
        SampledSpectrum s;
        for (double l : grid) {
            s.wavelengthNm.push_back(l);
            s.value.push_back(60.0 + 40.0 * std::sin(l / 37.0) +
                              (std::abs(l - 545.0) < 8.0 ? 300.0 : 0.0));
        }
        s.value.front() = 0.01; // the ends far from the rest: any leak of them shows
        s.value.back() = 900.0;
        auto r = resampleToWorkingGrid(s, "coarse", GridSampling::BandAverage);
        ASSERT_TRUE(r) << r.error().message;
        for (std::size_t b = 0; b < kBands; ++b) {
            EXPECT_NEAR((*r)[b], triangleByMidpoints(s, bandCentreNm(b)), 1e-6)
                    << "grid from " << grid.front() << " nm, band " << bandCentreNm(b) << " nm";
        }
    }
}

TEST(Resample, RejectsTooNarrowRange)
{
    SampledSpectrum s{{400.0, 500.0, 700.0}, {1.0, 1.0, 1.0}};
    auto r = resampleToWorkingGrid(s, "narrow.csv", GridSampling::AtBandCentre);
    ASSERT_FALSE(r);
    EXPECT_NE(r.error().message.find("narrow.csv"), std::string::npos);
    EXPECT_NE(r.error().message.find("380"), std::string::npos);
}

TEST(Resample, AtBandCentreTakesTheValueThereLinearBetweenSamples)
{
    // A ramp on an uneven grid: linear interpolation is exact on it, wherever the samples fall.
    SampledSpectrum s;
    for (double nm = 371.0; nm < 745.0; nm += (nm < 500.0 ? 3.7 : 11.3)) {
        s.wavelengthNm.push_back(nm);
        s.value.push_back(0.2 + 0.001 * nm);
    }
    auto r = resampleToWorkingGrid(s, "ramp", GridSampling::AtBandCentre);
    ASSERT_TRUE(r) << r.error().message;
    for (std::size_t i = 0; i < kBands; ++i) {
        EXPECT_NEAR((*r)[i], 0.2 + 0.001 * bandCentreNm(i), 1e-12) << bandCentreNm(i);
    }
    // On 5 nm data a band centre is a sample: taken as it is, where the band average would take
    // 1/4, 1/2, 1/4 of three.
    SampledSpectrum comb;
    for (int nm = 380; nm <= 730; nm += 5) {
        comb.wavelengthNm.push_back(nm);
        comb.value.push_back(nm % 10 == 0 ? 1.0 : 0.0);
    }
    auto at = resampleToWorkingGrid(comb, "comb", GridSampling::AtBandCentre);
    auto avg = resampleToWorkingGrid(comb, "comb", GridSampling::BandAverage);
    ASSERT_TRUE(at && avg);
    EXPECT_EQ((*at)[10], 1.0);
    EXPECT_DOUBLE_EQ((*avg)[10], 0.5);
}

// The CIE 13.3 test colours under D65, each computed two ways: on the working grid (the 10 nm
// observer, D65 averaged over each band, the reflectance as loaded) and from the 5 nm tables
// themselves with the 1 nm observer's 5 nm rows, 380-780 nm (an independent sum). CIELAB of each
// against its own white, so that only the grid differs.
std::vector<double> tcsGridErrors(GridSampling reflectanceSampling)
{
    auto obs = loadCie1931(dataDir());
    auto cmf = loadSpectralCsv(dataDir() / "spectra" / "cie1931_2deg_cmf_1nm_360_830.csv");
    auto ill = loadSpectralCsv(dataDir() / "spectra" / "cie_illuminants_A_D50_D65_5nm_300_780.csv");
    auto tcs = loadSpectralCsv(dataDir() / "spectra" / "cie_tcs01_14_5nm_360_830.csv");
    EXPECT_TRUE(obs && cmf && ill && tcs);
    if (!obs || !cmf || !ill || !tcs) {
        return {};
    }
    const Spectrum d65 = *ill->spectrum("D65", GridSampling::BandAverage);
    const Xyz white10 = spectrumToXyz(*obs, d65);
    const auto at5 = [](const SpectralTable& t, const std::string& column, double nm) {
        const auto v = *t.values(column);
        const auto it = std::find(t.wavelengthNm.begin(), t.wavelengthNm.end(), nm);
        return v[static_cast<std::size_t>(it - t.wavelengthNm.begin())];
    };
    const auto sum5 = [&](const std::string* column) {
        Xyz xyz{0.0};
        for (double nm = 380.0; nm <= 780.0; nm += 5.0) {
            const double p = at5(*ill, "D65", nm) * (column ? at5(*tcs, *column, nm) : 1.0);
            xyz.x += p * at5(*cmf, "xbar", nm);
            xyz.y += p * at5(*cmf, "ybar", nm);
            xyz.z += p * at5(*cmf, "zbar", nm);
        }
        return xyz;
    };
    const Xyz white5 = sum5(nullptr);
    std::vector<double> de;
    for (const auto& name : tcs->columns) {
        const Spectrum r = *tcs->spectrum(name, reflectanceSampling);
        const Lab grid = xyzToLab(spectrumToXyz(*obs, d65 * r), white10);
        const Lab fine = xyzToLab(sum5(&name), white5);
        de.push_back(ciede2000(grid, fine));
    }
    return de;
}

TEST(Resample, ReflectancesAtTheBandCentresKeepTheirFiveNanometreColours)
{
    const auto at = tcsGridErrors(GridSampling::AtBandCentre);
    const auto avg = tcsGridErrors(GridSampling::BandAverage);
    ASSERT_EQ(at.size(), 14u);
    ASSERT_EQ(avg.size(), 14u);
    const auto mean = [](const std::vector<double>& v) {
        return std::accumulate(v.begin(), v.end(), 0.0) / static_cast<double>(v.size());
    };
    const double maxAt = *std::max_element(at.begin(), at.end());
    std::printf("[ grid ] TCS01-14 under D65, 10 nm grid against 5 nm sums: dE00 mean %.3f max "
                "%.3f at the band centres, %.3f / %.3f band-averaged\n",
                mean(at), maxAt, mean(avg), *std::max_element(avg.begin(), avg.end()));
    // colour-notes: the 10 nm grid's own floor on smooth lights is about 0.02 mean, 0.09 max.
    EXPECT_LT(mean(at), 0.05);
    EXPECT_LT(maxAt, 0.15);
    EXPECT_LT(mean(at), 0.6 * mean(avg));
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
    auto a = t->spectrum("A", GridSampling::BandAverage);
    ASSERT_TRUE(a);
    const Xyz w = spectrumToXyz(*obs, *a);
    const double sum = w.x + w.y + w.z;
    EXPECT_NEAR(w.x / sum, 0.44757, 1e-3);
    EXPECT_NEAR(w.y / sum, 0.40745, 1e-3);
}

} // namespace
} // namespace replica::pipeline::colour
