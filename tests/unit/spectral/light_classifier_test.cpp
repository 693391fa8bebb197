// Tests of the light classifier: shape distance, recognition under noise, unknown lights,
// hysteresis.
#include <cmath>

#include <pipeline/base/data_dir.h>
#include <pipeline/colour/cct.h>
#include <pipeline/offline/spectral/classifier_study.h>
#include <pipeline/spectral/reference_sets.h>

#include <gtest/gtest.h>

namespace replica::pipeline::spectral {
namespace {

std::vector<StoredLight> boothLights()
{
    std::vector<StoredLight> out;
    for (const char* n : {"A", "F8", "F7"}) {
        auto l = loadCieIlluminant(dataDir(), n);
        EXPECT_TRUE(l);
        out.push_back({n, *l});
    }
    return out;
}

TEST(SpectralShapeDistance, ClosedForms)
{
    // Unit mean over n = 36 bands, then RMS difference.
    const double n = static_cast<double>(colour::kBands);
    Spectrum a;
    Spectrum b;
    a[3] = 2.0;
    b[10] = 5.0;
    // a -> n at band 3, b -> n at band 10: RMS of two differences of n is sqrt(2 n).
    EXPECT_NEAR(spectralShapeDistance(a, b), std::sqrt(2.0 * n), 1e-12);
    EXPECT_NEAR(spectralShapeDistance(a, a * 7.0), 0.0, 1e-15); // scale does not matter
    Spectrum c = a;
    c[10] = 2.0; // c -> n/2 at bands 3 and 10: differences n/2 twice, RMS sqrt(n / 2)
    EXPECT_NEAR(spectralShapeDistance(a, c), std::sqrt(n / 2.0), 1e-12);
    Spectrum noisy = a;
    noisy[20] = -0.3; // negative (noise) bands carry no shape
    EXPECT_NEAR(spectralShapeDistance(a, noisy), 0.0, 1e-15);
    EXPECT_TRUE(std::isinf(spectralShapeDistance(a, Spectrum{})));
}

TEST(LightClassifier, RejectsBadSetups)
{
    EXPECT_FALSE(LightClassifier::create({}));
    EXPECT_FALSE(LightClassifier::create({{"dark", Spectrum{}}}));
    LightClassifierParams p;
    p.releaseDistance = p.acceptDistance / 2;
    auto r = LightClassifier::create(boothLights(), p);
    ASSERT_FALSE(r);
    EXPECT_NE(r.error().message.find("acceptDistance <= releaseDistance"), std::string::npos);
}

TEST(LightClassifier, BoothLightsRecognisedUnderDataSheetNoise)
{
    const auto lights = boothLights();
    const auto m = classifierConfusion(lights, {}, BandNoiseParams{}, 300, 11);
    for (std::size_t t = 0; t < lights.size(); ++t) {
        EXPECT_EQ(m.counts[t][t], 300) << lights[t].name;
    }
}

TEST(LightClassifier, OtherLightsAreUnknown)
{
    auto c = LightClassifier::create(boothLights());
    ASSERT_TRUE(c);
    for (const char* other : {"LED-B4", "F11", "D65", "F2"}) {
        auto l = loadCieIlluminant(dataDir(), other);
        ASSERT_TRUE(l);
        EXPECT_EQ(c->nearest(*l).name, "unknown") << other;
    }
    // About a 125 K step from A (2856 K) is the edge: 2900 K is still A, 3000 K is not.
    EXPECT_EQ(c->nearest(colour::planckianSpectrum(2900.0)).name, "A");
    EXPECT_EQ(c->nearest(colour::planckianSpectrum(3000.0)).name, "unknown");
}

TEST(LightClassifier, HysteresisNeedsConfirmationAndHoldsNearTheEdge)
{
    const auto lights = boothLights();
    LightClassifierParams p;
    auto c = LightClassifier::create(lights, p);
    ASSERT_TRUE(c);
    const Spectrum a = lights[0].spd;
    // Starts unknown; A must win confirmSamples times in a row.
    for (int i = 1; i < p.confirmSamples; ++i) {
        EXPECT_EQ(c->update(a).name, "unknown");
    }
    EXPECT_EQ(c->update(a).name, "A");
    // A Planckian at 3030 K lies between accept (0.05) and release (0.08): alone it would be
    // unknown, but once A is recognised it is kept, however long it lasts.
    const Spectrum edge = colour::planckianSpectrum(3030.0);
    const double d = spectralShapeDistance(edge, a);
    ASSERT_GT(d, p.acceptDistance);
    ASSERT_LT(d, p.releaseDistance);
    EXPECT_EQ(c->nearest(edge).name, "unknown");
    for (int i = 0; i < 20; ++i) {
        EXPECT_EQ(c->update(i % 2 == 0 ? edge : a).name, "A");
    }
    // A single sample of another light does not switch; confirmSamples in a row do.
    const Spectrum f7 = lights[2].spd;
    EXPECT_EQ(c->update(f7).name, "A");
    EXPECT_EQ(c->update(a).name, "A");
    for (int i = 1; i < p.confirmSamples; ++i) {
        EXPECT_EQ(c->update(f7).name, "A");
    }
    EXPECT_EQ(c->update(f7).name, "F7");
    c->reset();
    EXPECT_EQ(c->currentClassification().name, "unknown");
    EXPECT_EQ(c->current(), -1);
}

TEST(LightClassifier, NoFlickerAtTenTimesTheDataSheetNoise)
{
    const auto lights = boothLights();
    BandNoiseParams noise;
    noise.noiseScale = 10.0;
    for (const auto& l : lights) {
        EXPECT_EQ(classifierFlicker(lights, {}, noise, l.spd, 400, 21), 0) << l.name;
    }
    // A light sitting right at the accept threshold, where single samples fall either side.
    const Spectrum edge = colour::planckianSpectrum(2985.0);
    EXPECT_LE(classifierFlicker(lights, {}, noise, edge, 400, 22), 1);
}

TEST(BandNoise, DeterministicAndScaledByTheNoiseKnob)
{
    auto a = loadCieIlluminant(dataDir(), "A");
    ASSERT_TRUE(a);
    NoiseSource r1(5);
    NoiseSource r2(5);
    BandNoiseParams p;
    const Spectrum s1 = senseWithNoise(*a, p, r1);
    const Spectrum s2 = senseWithNoise(*a, p, r2);
    EXPECT_EQ(s1.v, s2.v);
    p.noiseScale = 0.0;
    NoiseSource r3(5);
    const Spectrum clean = senseWithNoise(*a, p, r3);
    for (std::size_t i = 0; i < colour::kBands; ++i) {
        EXPECT_NEAR(clean[i], (*a)[i], 1e-12 * (*a)[i]);
    }
    // Gaussian source: mean ~0, variance ~1 over many draws.
    NoiseSource g(9);
    double sum = 0.0;
    double sum2 = 0.0;
    constexpr int kN = 20000;
    for (int i = 0; i < kN; ++i) {
        const double x = g.gaussian();
        sum += x;
        sum2 += x * x;
    }
    EXPECT_NEAR(sum / kN, 0.0, 0.03);
    EXPECT_NEAR(sum2 / kN, 1.0, 0.05);
}

} // namespace
} // namespace replica::pipeline::spectral
