// Tests of the metameric pairs: the shipped target matches under A and differs under D65, both in
// the full-spectral calculation and through the K = 6 rendering path.
#include <pipeline/base/data_dir.h>
#include <pipeline/colour/ciede2000.h>
#include <pipeline/offline/spectral/metamers.h>
#include <pipeline/spectral/representation_catalogue.h>

#include <gtest/gtest.h>

namespace replica::pipeline::spectral {
namespace {

// CIEDE2000 of two reflectances as the renderer would show them under 'light' with 'rep'.
double renderedDifference(const Observer& obs,
                          const Representation& rep,
                          const Spectrum& light,
                          const Spectrum& a,
                          const Spectrum& b)
{
    const auto m = rep.lightVectors(light);
    const Xyz white =
            colour::spectrumToXyz(obs, light) * (1.0 / colour::spectrumToXyz(obs, light).y);
    return colour::ciede2000(colour::xyzToLab(shade(rep.encode(a), m), white),
                             colour::xyzToLab(shade(rep.encode(b), m), white));
}

TEST(Metamers, ShippedTargetSurvivesTheShippedRepresentations)
{
    auto obs = colour::loadCie1931(dataDir());
    auto a = loadCieIlluminant(dataDir(), "A");
    auto d65 = loadCieIlluminant(dataDir(), "D65");
    auto set = loadNamedSpectra(dataDir() / "scenes" / "metamers" / "metamers_A_D65.csv",
                                colour::GridSampling::AtBandCentre);
    ASSERT_TRUE(obs && a && d65);
    ASSERT_TRUE(set) << set.error().message;
    ASSERT_GE(set->size(), 8u);
    ASSERT_EQ(set->size() % 2, 0u);
    for (std::size_t i = 0; i < set->size(); i += 2) {
        const Spectrum& x = set->spectra[i];
        const Spectrum& y = set->spectra[i + 1];
        for (std::size_t l = 0; l < colour::kBands; ++l) {
            EXPECT_GE(x[l], 0.0);
            EXPECT_LE(y[l], 1.0);
        }
        // The file keeps 6 decimals, so the match is exact to about 1e-4.
        EXPECT_LT(reflectancePairDifference(*obs, *a, x, y), 0.01) << set->names[i];
        EXPECT_GE(reflectancePairDifference(*obs, *d65, x, y), 3.0) << set->names[i];
        // In the fixed basis the pairs were found in, and in the one the appliance renders with.
        for (const char* name : {kDefaultRepresentation, kApplianceRepresentation}) {
            auto rep = makeRepresentation(dataDir(), *obs, *d65, name);
            ASSERT_TRUE(rep) << name;
            EXPECT_LT(renderedDifference(*obs, **rep, *a, x, y), 0.01) << set->names[i] << name;
            EXPECT_GE(renderedDifference(*obs, **rep, *d65, x, y), 3.0) << set->names[i] << name;
        }
    }
}

TEST(Metamers, NaiveRgbCannotShowTheMismatch)
{
    // Why the target needs a spectral pipeline: reduced to RGB, a pair that matches under A matches
    // under every light (the RGB of each is computed once, under D65, and then scaled by the
    // light).
    auto obs = colour::loadCie1931(dataDir());
    auto a = loadCieIlluminant(dataDir(), "A");
    auto d65 = loadCieIlluminant(dataDir(), "D65");
    auto set = loadNamedSpectra(dataDir() / "scenes" / "metamers" / "metamers_A_D65.csv",
                                colour::GridSampling::AtBandCentre);
    ASSERT_TRUE(obs && a && d65 && set);
    auto rgb = makeNaiveRgb(*obs, *d65);
    // Under A the RGB pipeline already shows them as different (it sees their D65 colours): it
    // cannot represent the match at all.
    EXPECT_GT(renderedDifference(*obs, *rgb, *a, set->spectra[0], set->spectra[1]), 3.0);
}

TEST(Metamers, FinderKeepsTheMatchExactInsideTheBasis)
{
    auto obs = colour::loadCie1931(dataDir());
    auto a = loadCieIlluminant(dataDir(), "A");
    auto d65 = loadCieIlluminant(dataDir(), "D65");
    auto basis = colour::loadDefaultChannelBasis(dataDir());
    auto seeds = loadReflectanceSet(dataDir(), "tcs14");
    ASSERT_TRUE(obs && a && d65 && basis && seeds);
    const auto pairs = findMetamerPairs(*obs, *basis, *a, *d65, *seeds, 4, 3.0, 5.0);
    ASSERT_FALSE(pairs.empty());
    for (const auto& p : pairs) {
        EXPECT_LT(p.de00Match, 1e-6) << p.name;
        EXPECT_NEAR(p.de00Mismatch, 5.0, 0.01) << p.name;
        EXPECT_NEAR(reflectancePairDifference(*obs, *d65, p.a, p.b), p.de00Mismatch, 1e-12);
    }
}

} // namespace
} // namespace replica::pipeline::spectral
