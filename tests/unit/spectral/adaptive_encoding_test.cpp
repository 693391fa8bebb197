// Tests of the light-adaptive K = 6 encoding: exact for the light it was built for (any
// reflectance), graceful for another light, stable for degenerate lights, clear errors.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>

#include <pipeline/base/data_dir.h>
#include <pipeline/colour/ciede2000.h>
#include <pipeline/colour/cielab.h>
#include <pipeline/offline/spectral/accuracy.h>
#include <pipeline/offline/spectral/basis_fit.h>
#include <pipeline/spectral/adaptive_encoding.h>
#include <pipeline/spectral/light_classifier.h>
#include <pipeline/spectral/representation_catalogue.h>

#include <gtest/gtest.h>

namespace replica::pipeline::spectral {
namespace {

using colour::kBands;
using colour::kChannels;

class Adaptive : public ::testing::Test
{
protected:
    static void SetUpTestSuite()
    {
        auto e = AdaptiveEncoder::createDefault(dataDir());
        ASSERT_TRUE(e) << e.error().message;
        encoder_ = new AdaptiveEncoder(std::move(*e));
    }
    static void TearDownTestSuite()
    {
        delete encoder_;
        encoder_ = nullptr;
    }
    void SetUp() override
    {
        auto o = colour::loadCie1931(dataDir());
        auto d = loadCieIlluminant(dataDir(), "D65");
        auto cc = loadReflectanceSet(dataDir(), "colorchecker");
        auto tcs = loadReflectanceSet(dataDir(), "tcs14");
        auto ces = loadReflectanceSet(dataDir(), "ces99");
        ASSERT_TRUE(o && d && cc && tcs && ces);
        obs_ = *o;
        d65_ = *d;
        cc_ = *cc;
        tcs_ = *tcs;
        ces_ = *ces;
    }
    static Spectrum light(const std::string& name)
    {
        auto l = loadCieIlluminant(dataDir(), name);
        EXPECT_TRUE(l) << name;
        return l ? *l : Spectrum{};
    }
    // Largest |XYZ error| / Y(white) over a set, for surfaces encoded with 'basis' and shaded
    // under 'light' exactly as the renderer does (channelToXyz), against the 36-band sum.
    double worstXyzError(const colour::ChannelBasis& basis,
                         const Spectrum& light,
                         const NamedSpectra& set) const
    {
        const auto m = colour::channelToXyz(basis, obs_, light);
        const double y = colour::spectrumToXyz(obs_, light).y;
        double worst = 0.0;
        for (const auto& r : set.spectra) {
            const Xyz ref = colour::spectrumToXyz(obs_, light * r) * (1.0 / y);
            const auto c = colour::projectReflectance(basis, r);
            Xyz got{0.0};
            for (std::size_t k = 0; k < kChannels; ++k) {
                got += m[k] * c[k];
            }
            worst = std::max({worst, std::abs(got.x - ref.x), std::abs(got.y - ref.y),
                              std::abs(got.z - ref.z)});
        }
        return worst;
    }

    static AdaptiveEncoder* encoder_;
    Observer obs_;
    Spectrum d65_;
    NamedSpectra cc_, tcs_, ces_;
};

AdaptiveEncoder* Adaptive::encoder_ = nullptr;

// The goal of issue 3 (mean <= 0.05, max <= 0.3) met with room to spare on every light, spiky
// fluorescents, LEDs and lights no fit has seen included: the encoding is exact for its light.
TEST_F(Adaptive, ExactForTheLightItWasBuiltForOnColorCheckerAndTcs)
{
    auto rep = makeRepresentation(dataDir(), obs_, d65_, "adaptive_k6");
    ASSERT_TRUE(rep) << rep.error().message;
    for (const char* name :
         {"A", "D50", "D65", "F2", "F7", "F8", "F11", "LED-B4", "F12", "FL3.15", "LED-RGB1"}) {
        for (const NamedSpectra* set : {&cc_, &tcs_}) {
            auto r = evaluateRepresentation(obs_, d65_, **rep, light(name), *set);
            ASSERT_TRUE(r) << r.error().message;
            EXPECT_LT(r->stats.max, 1e-6) << name << " " << set->source;
        }
        auto basis = encoder_->basisFor(light(name));
        ASSERT_TRUE(basis) << basis.error().message;
        EXPECT_LT(worstXyzError(*basis, light(name), cc_), 1e-10) << name;
    }
}

TEST_F(Adaptive, FirstThreeCoefficientsAreTheXyzAndTheMatrixIsTheIdentity)
{
    const Spectrum f11 = light("F11") * 37.0; // any scale
    auto basis = encoder_->basisFor(f11);
    ASSERT_TRUE(basis);
    const double y = colour::spectrumToXyz(obs_, f11).y;
    for (const auto& r : cc_.spectra) {
        const Xyz ref = colour::spectrumToXyz(obs_, f11 * r) * (1.0 / y);
        const auto c = colour::projectReflectance(*basis, r);
        EXPECT_NEAR(c[0], ref.x, 1e-12);
        EXPECT_NEAR(c[1], ref.y, 1e-12);
        EXPECT_NEAR(c[2], ref.z, 1e-12);
    }
    // Under its own light the six XYZ vectors are the unit vectors and three zeros: P W = I.
    const auto m = colour::channelToXyz(*basis, obs_, f11);
    const Xyz expected[kChannels] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1},
                                     {0, 0, 0}, {0, 0, 0}, {0, 0, 0}};
    for (std::size_t k = 0; k < kChannels; ++k) {
        EXPECT_NEAR(m[k].x, expected[k].x, 1e-9) << k;
        EXPECT_NEAR(m[k].y, expected[k].y, 1e-9) << k;
        EXPECT_NEAR(m[k].z, expected[k].z, 1e-9) << k;
    }
}

// Exactness is not a property of the training data: a reflectance no basis could represent (a
// single band, a step, random noise) is still exact under the light encoded for.
TEST_F(Adaptive, ExactForAnyReflectanceEvenOutsideEveryBasis)
{
    NamedSpectra odd;
    Spectrum spike;
    spike[23] = 1.0;
    Spectrum step;
    for (std::size_t l = 18; l < kBands; ++l) {
        step[l] = 0.9;
    }
    std::mt19937 rng(5);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    Spectrum noise;
    for (std::size_t l = 0; l < kBands; ++l) {
        noise[l] = u(rng);
    }
    odd.spectra = {spike, step, noise};
    odd.names = {"spike", "step", "noise"};
    for (const char* name : {"LED-B4", "F2"}) {
        auto basis = encoder_->basisFor(light(name));
        ASSERT_TRUE(basis);
        EXPECT_LT(worstXyzError(*basis, light(name), odd), 1e-10) << name;
        // The fixed default basis cannot do this (what the adaptive one is for).
        auto k6 = colour::loadDefaultChannelBasis(dataDir());
        ASSERT_TRUE(k6);
        EXPECT_GT(worstXyzError(*k6, light(name), odd), 1e-3) << name;
    }
}

// What the appliance shows between a light change and the end of the re-encode: surfaces encoded
// for the previous booth lamp, rendered under the new one. Measured 0.03-0.10 mean and <= 0.31
// max (docs/accuracy.md), the level of the fixed replica_k6 and 2-5 times better than the paper's
// six channels on the same lights (0.24-0.45 mean).
TEST_F(Adaptive, GracefulForAnotherBoothLight)
{
    const char* booth[] = {"A", "F8", "F7", "D65", "D50"};
    for (const char* from : booth) {
        auto basis = encoder_->basisFor(light(from));
        ASSERT_TRUE(basis);
        auto fixed = makeBasisRepresentation(obs_, *basis);
        for (const char* to : booth) {
            auto r = evaluateRepresentation(obs_, d65_, *fixed, light(to), cc_);
            ASSERT_TRUE(r);
            if (std::string(from) == to) {
                EXPECT_LT(r->stats.max, 1e-6);
                continue;
            }
            EXPECT_LT(r->stats.mean, 0.12) << from << " -> " << to;
            EXPECT_LT(r->stats.max, 0.35) << from << " -> " << to;
        }
    }
}

// With no light known the encoder's basis predicts what fitChannelBasis's does (same prior, same
// weighted lights), though computed by another route (eigenvectors of the prior, not Cholesky).
TEST_F(Adaptive, GeneralBasisMatchesTheLightAwareFit)
{
    NamedSpectra lights;
    BasisFitOptions options;
    for (const auto& name : evaluationLightNames()) {
        lights.names.push_back(name);
        lights.spectra.push_back(light(name));
        double w = 1.0;
        for (const auto& [n, v] : defaultLightWeights()) {
            w = n == name ? v : w;
        }
        options.lightWeights.push_back(w);
    }
    auto fit = fitChannelBasis(obs_, d65_, ces_, lights, options, "fit");
    ASSERT_TRUE(fit);
    const auto& general = encoder_->generalBasis();
    for (const char* name : {"A", "F11", "LED-RGB1"}) {
        const auto mg = colour::channelToXyz(general, obs_, light(name));
        const auto mf = colour::channelToXyz(*fit, obs_, light(name));
        for (const auto& r : cc_.spectra) {
            const auto cg = colour::projectReflectance(general, r);
            const auto cf = colour::projectReflectance(*fit, r);
            Xyz a{0.0}, b{0.0};
            for (std::size_t k = 0; k < kChannels; ++k) {
                a += mg[k] * cg[k];
                b += mf[k] * cf[k];
            }
            EXPECT_NEAR(a.x, b.x, 1e-9) << name;
            EXPECT_NEAR(a.y, b.y, 1e-9) << name;
            EXPECT_NEAR(a.z, b.z, 1e-9) << name;
        }
    }
}

// The float path the appliance uses: a 36-band image re-encoded for a light, shaded with the
// surface's own six XYZ vectors, agrees with the 36-band calculation to float rounding.
TEST_F(Adaptive, SurfaceReencodedInFloatIsExactToFloatRounding)
{
    ReflectanceImage img;
    img.width = 6;
    img.height = 4;
    for (const auto& r : cc_.spectra) {
        for (std::size_t l = 0; l < kBands; ++l) {
            img.bands.push_back(static_cast<float>(r[l]));
        }
    }
    const Spectrum f11 = light("F11");
    auto s = encodeSurface(*encoder_, img, f11);
    ASSERT_TRUE(s) << s.error().message;
    ASSERT_EQ(s->coeffs.size(), 24u * kChannels);
    EXPECT_EQ(s->width, 6);
    const auto m = colour::channelToXyz(s->basis, obs_, f11);
    for (std::size_t k = 0; k < kChannels; ++k) {
        EXPECT_EQ(s->toXyz[k].y, m[k].y);
    }
    const double y = colour::spectrumToXyz(obs_, f11).y;
    const Xyz white = colour::spectrumToXyz(obs_, f11) * (1.0 / y);
    double worst = 0.0;
    for (std::size_t i = 0; i < 24; ++i) {
        Spectrum r;
        for (std::size_t l = 0; l < kBands; ++l) {
            r[l] = static_cast<double>(img.bands[i * kBands + l]); // what the image holds
        }
        const Xyz ref = colour::spectrumToXyz(obs_, f11 * r) * (1.0 / y);
        Xyz got{0.0};
        for (std::size_t k = 0; k < kChannels; ++k) {
            got += s->toXyz[k] * static_cast<double>(s->coeffs[i * kChannels + k]);
        }
        worst = std::max(worst, colour::ciede2000(colour::xyzToLab(ref, white),
                                                  colour::xyzToLab(got, white)));
    }
    EXPECT_LT(worst, 1e-3); // float: ~1e-7 relative in XYZ
    // Bad sizes are refused, naming what was expected.
    ReflectanceImage bad = img;
    bad.bands.pop_back();
    auto e = encodeSurface(*encoder_, bad, f11);
    ASSERT_FALSE(e);
    EXPECT_EQ(e.error().message, "adaptive encoding: a 6 x 4 reflectance image needs 864 floats "
                                 "(36 bands per texel), it has 863");
}

// rendering-notes.md hard case 10 for the adaptive encoding: single- and two-band lights (fewer
// than three independent functionals), a near-degenerate one, and a sensed spectrum with negative
// bands all give a finite basis that is still exact for that light.
TEST_F(Adaptive, DegenerateLightsStayFiniteAndExact)
{
    Spectrum laser;
    laser[17] = 5.0; // 550 nm only: X, Y, Z all proportional
    Spectrum twoLines;
    twoLines[7] = 1.0;  // 450 nm
    twoLines[22] = 2.0; // 600 nm
    Spectrum nearLaser = laser;
    for (std::size_t l = 0; l < kBands; ++l) {
        nearLaser[l] += 1e-9 * static_cast<double>(l % 3);
    }
    Spectrum line30; // a 30 nm wide line: three independent but nearly parallel functionals
    line30[16] = line30[17] = line30[18] = 1.0;
    Spectrum led; // a narrow LED, 6 nm standard deviation at 480 nm
    for (std::size_t l = 0; l < kBands; ++l) {
        const double z = (static_cast<double>(l) - 10.0) / 0.6;
        led[l] = std::exp(-0.5 * z * z);
    }
    Spectrum noisy = light("F11");
    for (std::size_t l = 0; l < kBands; l += 3) {
        noisy[l] -= 0.3 * noisy.max();
    }
    for (const Spectrum* l : {&laser, &twoLines, &nearLaser, &line30, &led, &noisy}) {
        auto basis = encoder_->basisFor(*l);
        ASSERT_TRUE(basis) << basis.error().message;
        double biggest = 0.0;
        for (std::size_t k = 0; k < kChannels; ++k) {
            for (std::size_t b = 0; b < kBands; ++b) {
                ASSERT_TRUE(std::isfinite(basis->project[k][b]));
                ASSERT_TRUE(std::isfinite(basis->reconstruct[k][b]));
                biggest = std::max(biggest, std::abs(basis->reconstruct[k][b]));
            }
        }
        EXPECT_LT(biggest, 1e4);
        EXPECT_LT(worstXyzError(*basis, *l, cc_), 1e-8);
        // And it stays usable under an ordinary light.
        auto fixed = makeBasisRepresentation(obs_, *basis);
        auto r = evaluateRepresentation(obs_, d65_, *fixed, light("D65"), cc_);
        ASSERT_TRUE(r);
        EXPECT_TRUE(std::isfinite(r->stats.max));
    }
}

TEST_F(Adaptive, LightsWithoutLuminanceOrWithNaNAreClearErrors)
{
    const std::string dark = "adaptive encoding: the light has no luminance (Y <= 0); a dark or "
                             "all-zero spectrum cannot be encoded for, keep the previous encoding";
    for (const Spectrum& l : {Spectrum::constant(0.0), Spectrum::constant(-1.0)}) {
        auto b = encoder_->basisFor(l);
        ASSERT_FALSE(b);
        EXPECT_EQ(b.error().message, dark);
    }
    Spectrum nan = light("A");
    nan[4] = std::nan("");
    auto b = encoder_->basisFor(nan);
    ASSERT_FALSE(b);
    EXPECT_EQ(b.error().message,
              "adaptive encoding: the light's band at 420 nm is not a finite number");
    ReflectanceImage img{1, 1, std::vector<float>(kBands, 0.5f)};
    auto s = encodeSurface(*encoder_, img, Spectrum::constant(0.0));
    ASSERT_FALSE(s);
    EXPECT_EQ(s.error().message, dark);
    // The representation reports it through the accuracy path too.
    auto rep = makeRepresentation(dataDir(), obs_, d65_, "adaptive_k6");
    ASSERT_TRUE(rep);
    auto a = (*rep)->adaptedTo(Spectrum::constant(0.0));
    ASSERT_FALSE(a);
    EXPECT_EQ(a.error().message, dark);
}

TEST_F(Adaptive, EncoderRefusesBadTrainingData)
{
    NamedSpectra lights;
    lights.names = {"A"};
    lights.spectra = {light("A")};
    NamedSpectra few;
    few.names = {"a", "b"};
    few.spectra = {ces_.spectra[0], ces_.spectra[1]};
    auto e = AdaptiveEncoder::create(obs_, d65_, few, lights);
    ASSERT_FALSE(e);
    EXPECT_EQ(e.error().message, "adaptive encoder: needs at least 6 training reflectances, got 2");
    AdaptiveEncoderOptions options;
    options.lightWeights = {1.0, 2.0};
    e = AdaptiveEncoder::create(obs_, d65_, ces_, lights, options);
    ASSERT_FALSE(e);
    EXPECT_EQ(e.error().message, "adaptive encoder: 2 light weights for 1 lights");
    lights.spectra[0] = Spectrum::constant(0.0);
    e = AdaptiveEncoder::create(obs_, d65_, ces_, lights);
    ASSERT_FALSE(e);
    EXPECT_EQ(e.error().message, "adaptive encoder: every training light needs luminance (Y > 0)");
}

} // namespace
} // namespace replica::pipeline::spectral

namespace replica::pipeline::spectral {
namespace {

// The direct-sensor re-encode threshold: surfaces encoded for a light and shown under a light
// whose shape has drifted by kAdaptiveReencodeDistance (towards any other light of the issue, or
// by band noise) stay far inside the goal, so re-encoding only past it costs nothing
// visible; and the drift, once past it, is re-encoded exactly.
TEST_F(Adaptive, DriftUpToTheReencodeDistanceStaysFarInsideTheGoal)
{
    auto rep = makeRepresentation(dataDir(), obs_, d65_, "adaptive_k6");
    ASSERT_TRUE(rep);
    const auto names = evaluationLightNames();
    double worstMean = 0.0;
    double worstMax = 0.0;
    double worstMaxFarther = 0.0; // at twice the distance: the threshold is not vacuous
    std::mt19937 rng(7);
    std::normal_distribution<double> gauss(0.0, 1.0);
    for (const auto& from : names) {
        auto encoded = (*rep)->adaptedTo(light(from));
        ASSERT_TRUE(encoded) << encoded.error().message;
        std::vector<std::pair<Spectrum, bool>> shifted; // the light, at the threshold (or 2x)
        for (const auto& to : names) {
            for (double d : {kAdaptiveReencodeDistance, 2.0 * kAdaptiveReencodeDistance}) {
                auto s = shiftedLight(obs_, light(from), light(to), d);
                if (to == from) {
                    EXPECT_FALSE(s); // no distance at all towards itself
                    continue;
                }
                ASSERT_TRUE(s) << from << " -> " << to << ": " << s.error().message;
                EXPECT_NEAR(spectralShapeDistance(light(from), *s), d, 1e-9);
                shifted.emplace_back(*s, d == kAdaptiveReencodeDistance);
            }
        }
        // Band noise scaled to the same shape distance (what a noisy sensor reading looks like).
        for (int k = 0; k < 4; ++k) {
            Spectrum noise;
            for (std::size_t b = 0; b < kBands; ++b) {
                noise[b] = light(from)[b] * (1.0 + 0.1 * gauss(rng));
            }
            auto s = shiftedLight(obs_, light(from), noise, kAdaptiveReencodeDistance);
            ASSERT_TRUE(s) << s.error().message;
            shifted.emplace_back(*s, true);
        }
        for (const auto& [s, atThreshold] : shifted) {
            auto r = evaluateRepresentation(obs_, d65_, **encoded, s, cc_);
            ASSERT_TRUE(r) << r.error().message;
            if (atThreshold) {
                worstMean = std::max(worstMean, r->stats.mean);
                worstMax = std::max(worstMax, r->stats.max);
            } else {
                worstMaxFarther = std::max(worstMaxFarther, r->stats.max);
            }
        }
    }
    // Measured 0.0118 / 0.0402 at the threshold (max 0.070 at twice it); the goal
    // is mean <= 0.05, max <= 0.3.
    EXPECT_LE(worstMean, 0.015);
    EXPECT_LE(worstMax, 0.05);
    EXPECT_GT(worstMaxFarther, worstMax);
    std::printf("drift %.3f: worst mean %.4f, worst max %.4f; at %.3f: worst max %.4f\n",
                kAdaptiveReencodeDistance, worstMean, worstMax, 2.0 * kAdaptiveReencodeDistance,
                worstMaxFarther);
}

TEST_F(Adaptive, ShiftedLightRefusesWhatItCannotReach)
{
    EXPECT_FALSE(shiftedLight(obs_, Spectrum{}, light("A"), 0.01));
    EXPECT_FALSE(shiftedLight(obs_, light("A"), light("F11"), 0.0));
    auto far = shiftedLight(obs_, light("A"), light("A") * 2.0, 0.01);
    ASSERT_FALSE(far);
    EXPECT_NE(far.error().message.find("apart in shape"), std::string::npos) << far.error().message;
}

} // namespace
} // namespace replica::pipeline::spectral
