// The noise-robust fit on synthetic panels of known truth: several tone-curve shapes (GOG,
// sRGB-like piecewise, S-shaped), channel crosstalk, a black offset, meter noise 0 to 1 %. Every
// figure is the fitted model against the panel's own forward model, on colours and counts that
// were never measured, so nothing here compares the fit with itself.
#include <cmath>
#include <cstdio>
#include <random>

#include <pipeline/display/display_inverse.h>
#include <pipeline/display/xyz_difference.h>
#include <pipeline/offline/display/display_fit.h>
#include <pipeline/offline/display/synthetic_display.h>
#include <pipeline/offline/display/tone_fit.h>

#include <gtest/gtest.h>

namespace replica::pipeline::display {
namespace {

// The panel: three GOG tone curves, a black offset, sRGB-like primaries.
SyntheticDisplay gogPanel()
{
    SyntheticDisplay d = wideIpsGroundTruth();
    d.tone = SyntheticTone::Gog;
    d.gamma = {2.35, 2.2, 2.05};
    d.gogGain = {1.03, 1.0, 1.06};
    d.blackXyz = {0.45, 0.48, 0.70};
    d.interaction = 0.0;
    return d;
}

SyntheticDisplay srgbPanel()
{
    SyntheticDisplay d = gogPanel();
    d.tone = SyntheticTone::Srgb;
    d.gamma = {2.4, 2.4, 2.3};
    return d;
}

SyntheticDisplay sShapedPanel()
{
    SyntheticDisplay d = wideIpsGroundTruth(); // S-shaped power curves, 0.5 % crosstalk
    d.interaction = 0.0;
    return d;
}

SyntheticDisplay crosstalkPanel()
{
    return wideIpsGroundTruth(); // as above with its 0.5 % channel interaction
}

// The four panels by the names the sweeps print (docs/display.md's tables).
std::vector<std::pair<const char*, SyntheticDisplay>> namedPanels()
{
    return {{"gog", gogPanel()},
            {"srgb", srgbPanel()},
            {"s-shaped", sShapedPanel()},
            {"crosstalk", crosstalkPanel()}};
}

MeasurementSet measure(const SyntheticDisplay& d, double noise, std::uint64_t seed)
{
    MeasurementSet s;
    s.source = "synthetic";
    s.bitDepth = d.bitDepth;
    MeterNoise n;
    n.relative = noise;
    n.absoluteCdM2 = noise * 1.25; // 0.0025 cd/m^2 at 0.2 %: a colorimeter's floor
    s.rows = syntheticSession(d, n, SessionPlan{}, seed);
    for (std::size_t i = 0; i < s.rows.size(); ++i) {
        s.rows[i].line = static_cast<int>(i) + 2;
    }
    return s;
}

struct Figures {
    double truthMean = 0.0; // model vs panel, dE00, 400 unmeasured colours
    double truthMax = 0.0;
    double rampInverseMax = 0.0;        // counts, R, G, B and grey ramps at every count
    double rampInverseMaxClip = 0.0;    // the same through per-channel clipping, not hue-keeping
    double rampInverseMaxInGamut = 0.0; // hue-keeping, over the counts the model finds in gamut
    double colourInverseP95 = 0.0;      // counts, the 400 colours (in gamut), per-channel
    double colourInverseMax = 0.0;
    int rampWorstChannel = 0;
    int rampWorstCount = 0;
};

Figures evaluate(const DisplayModel& model, const SyntheticDisplay& truth)
{
    Figures f;
    const glm::dvec3 white = truth.forward(glm::dvec3(255.0));
    auto inv = DisplayInverse::build(model);
    EXPECT_TRUE(inv.has_value());
    if (!inv) {
        f.rampInverseMax = 1e9;
        return f;
    }
    std::mt19937_64 rng(4242);
    std::vector<double> colourErr;
    for (int i = 0; i < 400; ++i) {
        glm::dvec3 c;
        for (int k = 0; k < 3; ++k) {
            c[k] = static_cast<double>(rng() % 25501) / 100.0;
        }
        const double de = deltaE2000Xyz(model.forward(c), truth.forward(c), white);
        f.truthMean += de / 400.0;
        f.truthMax = std::max(f.truthMax, de);
        const auto r = inv->invert(truth.forward(c), GamutMode::HueKeeping, ToneInverse::Exact);
        if (r.inGamut()) {
            for (int k = 0; k < 3; ++k) {
                if (truth.toneResponse(k, c[k]) >= 1e-3) {
                    colourErr.push_back(std::abs(r.counts[k] - c[k]));
                }
            }
        }
    }
    std::sort(colourErr.begin(), colourErr.end());
    if (!colourErr.empty()) {
        f.colourInverseP95 = colourErr[colourErr.size() * 95 / 100];
        f.colourInverseMax = colourErr.back();
    }
    for (int ch = 0; ch < 4; ++ch) {
        for (int v = 1; v <= 255; ++v) {
            glm::dvec3 c(0.0);
            if (ch == 3) {
                c = glm::dvec3(v);
            } else {
                c[ch] = v;
            }
            const auto r = inv->invert(truth.forward(c), GamutMode::HueKeeping, ToneInverse::Exact);
            const auto rc = inv->invert(truth.forward(c), GamutMode::Clip, ToneInverse::Exact);
            for (int k = 0; k < 3; ++k) {
                if ((ch == 3 || k == ch) && truth.toneResponse(k, v) >= 1e-3) {
                    const double e = std::abs(r.counts[k] - c[k]);
                    if (e > f.rampInverseMax) {
                        f.rampInverseMax = e;
                        f.rampWorstChannel = ch;
                        f.rampWorstCount = v;
                    }
                    if (r.inGamut()) {
                        f.rampInverseMaxInGamut = std::max(f.rampInverseMaxInGamut, e);
                    }
                    f.rampInverseMaxClip =
                            std::max(f.rampInverseMaxClip, std::abs(rc.counts[k] - c[k]));
                }
            }
        }
    }
    return f;
}

DisplayModel fit(const SyntheticDisplay& panel,
                 double noise,
                 std::uint64_t seed,
                 ToneMethod method = ToneMethod::Robust)
{
    FitOptions o;
    o.toneMethod = method;
    auto m = fitDisplay(measure(panel, noise, seed), o);
    EXPECT_TRUE(m.has_value()) << m.error().message;
    return m ? *m : DisplayModel{};
}

// The figures of docs/display.md: every panel at 0, 0.2, 0.5 and 1 % noise, robust fit, the same
// without the matrix refinement, and the interpolating fit. About 30 s; run with
// --gtest_also_run_disabled_tests --gtest_filter=RobustFit.DISABLED_Table.
TEST(RobustFit, DISABLED_Table)
{
    const auto panels = namedPanels();
    for (const auto& [name, panel] : panels) {
        for (double noise : {0.0, 0.002, 0.005, 0.01}) {
            for (int method = 0; method < 3; ++method) {
                FitOptions o;
                o.toneMethod = method != 1 ? ToneMethod::Robust : ToneMethod::Interpolate;
                o.maxEvaluations = method == 2 ? 0 : o.maxEvaluations;
                auto m = fitDisplay(measure(panel, noise, 17), o);
                ASSERT_TRUE(m.has_value()) << m.error().message;
                const Figures f = evaluate(*m, panel);
                std::printf("%-10s %5.1f%% %-5s truth dE mean %.3f max %.3f | inverse ramps max "
                            "%.2f (%d@%d) clip %.2f in-gamut %.2f colours p95 %.2f max %.2f | "
                            "heldout %.3f/%.3f noiseDe %.3f "
                            "noise %.3f%% shapes %s %s %s expInv %.2f %.2f %.2f add %.3f (p99.9 "
                            "%.3f) %+.3f%% +- %.3f %s\n",
                            name, 100 * noise,
                            method == 0   ? "rob"
                            : method == 1 ? "old"
                                          : "noNM",
                            f.truthMean, f.truthMax, f.rampInverseMax, f.rampWorstChannel,
                            f.rampWorstCount, f.rampInverseMaxClip, f.rampInverseMaxInGamut,
                            f.colourInverseP95, f.colourInverseMax, m->fit.heldOutMeanDe00,
                            m->fit.heldOutMaxDe00, m->fit.heldOutNoiseMeanDe00, m->fit.noisePercent,
                            m->fit.toneShape[0].c_str(), m->fit.toneShape[1].c_str(),
                            m->fit.toneShape[2].c_str(), m->fit.inverseCountsMax[0],
                            m->fit.inverseCountsMax[1], m->fit.inverseCountsMax[2],
                            m->fit.additivityDe00, m->fit.additivityNoiseDe00,
                            m->fit.additivityLuminancePercent,
                            m->fit.additivityLuminanceSigmaPercent,
                            m->fit.additiveWithinNoise ? "additive" : "NOT");
            }
        }
    }
}

// Every shape over 20 seeds (1001..1020) at each noise level: the worst ramp inverse (counts,
// hue-keeping and clipped), the worst model-vs-panel dE00 on 400 unmeasured colours, and the worst
// held-out dE00 the fit reports against its noisy held-out readings; and the same fits' inverse
// through the mapping without the edge tolerance (what the inverse was before it). The figures
// of docs/display.md (and docs/display_noise.csv and .png, through
// tools/display_noise_plot.sh); about 3 minutes; run with
// --gtest_also_run_disabled_tests --gtest_filter=RobustFit.DISABLED_Seeds.
TEST(RobustFit, DISABLED_Seeds)
{
    const auto panels = namedPanels();
    for (const auto& [name, panel] : panels) {
        for (double noise : {0.0, 0.001, 0.002, 0.005, 0.0075, 0.01}) {
            Figures worst;
            double withoutTolerance = 0.0; // the same fits, the mapping without the edge tolerance
            double heldOut = 0.0;
            double tolerance = 0.0;
            std::uint64_t worstSeed = 0;
            for (std::uint64_t seed = 1001; seed <= 1020; ++seed) {
                const DisplayModel m = fit(panel, noise, seed);
                const Figures f = evaluate(m, panel);
                DisplayModel bare = m;
                bare.gamutEdgeTolerance = 0.0;
                bare.gamutEdgeFloor = 0.0;
                withoutTolerance = std::max(withoutTolerance, evaluate(bare, panel).rampInverseMax);
                if (f.rampInverseMax > worst.rampInverseMax) {
                    worst.rampInverseMax = f.rampInverseMax;
                    worst.rampWorstChannel = f.rampWorstChannel;
                    worst.rampWorstCount = f.rampWorstCount;
                    worstSeed = seed;
                }
                worst.rampInverseMaxClip = std::max(worst.rampInverseMaxClip, f.rampInverseMaxClip);
                worst.truthMax = std::max(worst.truthMax, f.truthMax);
                worst.colourInverseP95 = std::max(worst.colourInverseP95, f.colourInverseP95);
                heldOut = std::max(heldOut, m.fit.heldOutMaxDe00);
                tolerance = std::max(tolerance, m.gamutEdgeTolerance);
            }
            std::printf("%-10s %4.2f%%: inverse max %.2f (seed %llu, %d@%d) clipped %.2f, "
                        "without the edge tolerance %.2f | "
                        "colours p95 %.2f | truth dE00 max %.3f | held-out (noisy readings) max "
                        "%.3f | edge tolerance up to %.4f\n",
                        name, 100 * noise, worst.rampInverseMax,
                        static_cast<unsigned long long>(worstSeed), worst.rampWorstChannel,
                        worst.rampWorstCount, worst.rampInverseMaxClip, withoutTolerance,
                        worst.colourInverseP95, worst.truthMax, heldOut, tolerance);
        }
    }
}

// The crosstalk decision per seed (1001..1020) at 0 and 0.2 % noise on every panel: the family
// kept, the uniform coefficient over its standard error (z), the held-out gain, C's first entry,
// the worst ramp inverse (counts) and truth dE00. The figures of docs/display.md's fit step 5;
// about 40 s; run with --gtest_also_run_disabled_tests
// --gtest_filter=RobustFit.DISABLED_CrosstalkSeeds.
TEST(RobustFit, DISABLED_CrosstalkSeeds)
{
    const auto panels = namedPanels();
    for (const auto& [name, panel] : panels) {
        for (double noise : {0.0, 0.002}) {
            for (std::uint64_t seed = 1001; seed <= 1020; ++seed) {
                const DisplayModel m = fit(panel, noise, seed);
                const Figures f = evaluate(m, panel);
                std::printf(
                        "%-10s %4.2f%% %llu %-8s z %6.2f gain %.4f c00 %+.6f inv %.2f truth %.3f\n",
                        name, 100 * noise, static_cast<unsigned long long>(seed),
                        m.fit.crosstalkModel.c_str(), m.fit.crosstalkZ, m.fit.crosstalkGainDe00,
                        m.crosstalk[0][0], f.rampInverseMax, f.truthMax);
            }
        }
    }
}

TEST(RobustFit, NoiseFreeMeasurementsFitExactly)
{
    // GOG curves are in the model family: exact to rounding. The others are interpolated.
    const Figures gog = evaluate(fit(gogPanel(), 0.0, 3), gogPanel());
    EXPECT_LT(gog.truthMax, 1e-3);
    EXPECT_LT(gog.rampInverseMax, 1e-3);
    for (const auto& panel : {srgbPanel(), sShapedPanel()}) {
        const DisplayModel m = fit(panel, 0.0, 3);
        const Figures f = evaluate(m, panel);
        EXPECT_LT(f.truthMax, 0.02);
        EXPECT_LT(f.rampInverseMax, 0.1);
        EXPECT_LT(m.fit.noisePercent, 1e-5);
        EXPECT_LT(m.fit.heldOutMaxDe00, 0.02);
    }
}

TEST(RobustFit, AveragesAColorimetersNoise)
{
    // 0.2 % per XYZ component (plus 0.0025 cd/m^2): the goal is held-out dE00 max <= 0.5
    // and the inverse within 0.5 counts. Against the truth on 400 unmeasured colours, and every
    // count of the R, G, B and grey ramps where the light is at least 0.1 % of full drive.
    for (const auto& panel : {gogPanel(), srgbPanel(), sShapedPanel()}) {
        const double inverseLimit = 0.5;
        const Figures robust = evaluate(fit(panel, 0.002, 17), panel);
        const Figures old = evaluate(fit(panel, 0.002, 17, ToneMethod::Interpolate), panel);
        EXPECT_LE(robust.truthMax, 0.5);
        EXPECT_LT(robust.truthMean, 0.05);
        EXPECT_LE(robust.rampInverseMax, inverseLimit);
        EXPECT_LE(robust.colourInverseP95, 0.5);
        // And better than interpolating through the noise.
        EXPECT_LT(robust.truthMean, 0.7 * old.truthMean);
        EXPECT_LT(robust.truthMax, old.truthMax);
    }
}

TEST(RobustFit, InverseAcrossSeedsAndShapes)
{
    // 0.2 % noise, eight seeds per panel (the goal is 0.5 counts and dE00 0.5). The
    // targets are the panel's own XYZ at every count of the R, G, B and grey ramps (where the
    // light is at least 0.1 % of full drive), inverted through the fitted model, against the count
    // that made them; dE00 is the fitted model against the panel on 400 colours never measured.
    // Over seeds 1001..1020 the worst is GOG 0.18, sRGB-like 0.25, S-shaped 0.35 counts
    // (DISABLED_Seeds). The crosstalk panel (0.5 % loss at white) gets its one-parameter
    // crosstalk term on every seed (its coefficient 10 to 22 standard errors from zero over seeds
    // 1001..1020, DISABLED_CrosstalkSeeds), worst 0.30 counts here and 0.35 over 1001..1020; the
    // additive model would miss white by up to 0.83 counts. Its coefficient, -0.005 / 3 on this
    // panel, lands within three of its standard errors (about 0.00013 at this noise).
    // The hue-keeping mapping must cost nothing over per-channel clipping on colours the panel
    // makes (the edge tolerance).
    for (const auto& [panel, inverseLimit] :
         {std::pair{gogPanel(), 0.5}, std::pair{srgbPanel(), 0.5}, std::pair{sShapedPanel(), 0.5},
          std::pair{crosstalkPanel(), 0.5}}) {
        for (std::uint64_t seed = 1001; seed <= 1008; ++seed) {
            const DisplayModel m = fit(panel, 0.002, seed);
            if (panel.interaction > 0.0) {
                EXPECT_EQ(m.fit.crosstalkModel, "uniform") << seed;
                EXPECT_GT(m.fit.crosstalkZ, 3.0) << seed;
                EXPECT_NEAR(m.crosstalk[0][0], -0.005 / 3.0, 0.0004) << seed;
            }
            const Figures f = evaluate(m, panel);
            EXPECT_LE(f.truthMax, 0.5) << seed;
            EXPECT_LE(f.rampInverseMax, inverseLimit) << seed;
            EXPECT_LE(f.rampInverseMax, f.rampInverseMaxClip + 0.05)
                    << seed << ": the mapping moved a colour the panel makes";
            EXPECT_GT(m.gamutEdgeTolerance, 1e-4) << seed;
            EXPECT_LT(m.gamutEdgeTolerance, 0.02) << seed;
        }
    }
    // Noise-free: no tolerance to speak of, and the inverse exact.
    const DisplayModel exact = fit(gogPanel(), 0.0, 1001);
    EXPECT_LT(exact.gamutEdgeTolerance, 1e-6);
    EXPECT_LT(evaluate(exact, gogPanel()).rampInverseMax, 1e-3);
}

// The crosstalk term is kept only where its coefficient stands out of the noise and
// cross-validation says it predicts better: additive panels
// stay additive (C = 0 exactly, with and without noise); the crosstalk panel's loss, 0.5 % of white
// spread over the three products in the white's colour (synthetic_display.cpp), is C = -0.005 / 3
// in every entry, recovered noise-free by the one-parameter family.
TEST(RobustFit, CrosstalkOnlyWhereHeldOutErrorSaysSo)
{
    for (const auto& panel : {gogPanel(), srgbPanel(), sShapedPanel()}) {
        for (std::uint64_t seed = 1001; seed <= 1008; ++seed) {
            // Noise-free, the coefficient can sit several of its tiny standard errors from zero
            // (interpolated tone curves); the held-out gain floor keeps the term out.
            EXPECT_FALSE(fit(panel, 0.0, seed).hasCrosstalk()) << seed;
            const DisplayModel m = fit(panel, 0.002, seed);
            // At a meter's noise the coefficient is within three standard errors of zero.
            EXPECT_LT(m.fit.crosstalkZ, 3.0) << seed;
            EXPECT_EQ(m.crosstalk, glm::dmat3(0.0)) << seed;
            EXPECT_EQ(m.fit.crosstalkModel, "none") << seed;
        }
    }
    const DisplayModel exact = fit(crosstalkPanel(), 0.0, 1001);
    EXPECT_EQ(exact.fit.crosstalkModel, "uniform");
    for (int col = 0; col < 3; ++col) {
        for (int row = 0; row < 3; ++row) {
            EXPECT_NEAR(exact.crosstalk[col][row], -0.005 / 3.0, 0.02 * 0.005 / 3.0);
        }
    }
    // And it makes the noise-free inverse exact where the additive model missed by 0.78 counts.
    EXPECT_LT(evaluate(exact, crosstalkPanel()).rampInverseMax, 0.02);
}

TEST(RobustFit, EstimatesTheMetersNoise)
{
    for (double noise : {0.002, 0.01}) {
        const DisplayModel m = fit(srgbPanel(), noise, 5);
        EXPECT_NEAR(m.fit.noisePercent, 100.0 * noise, 15.0 * noise) << noise;
        // The held-out readings' own noise is of the order of the held-out error (30 held-out
        // colours, one draw each: this seed's draws come out a third below the expectation).
        EXPECT_GT(m.fit.heldOutNoiseMeanDe00, 0.5 * m.fit.heldOutMeanDe00);
        EXPECT_LT(m.fit.heldOutNoiseMeanDe00, 2.0 * m.fit.heldOutMeanDe00);
        for (int c = 0; c < 3; ++c) {
            EXPECT_GT(m.fit.inverseCountsRms[static_cast<std::size_t>(c)], 0.0);
            EXPECT_EQ(m.fit.toneShape[static_cast<std::size_t>(c)].empty(), false);
        }
    }
}

TEST(RobustFit, AdditivityIsJudgedAgainstTheNoise)
{
    // Noise-free and additive, with a large black: white = black + R + G + B exactly, so the
    // check reads 0 only if black is counted once.
    SyntheticDisplay bright = gogPanel();
    bright.blackXyz = {4.5, 5.0, 6.0};
    const DisplayModel exact = fit(bright, 0.0, 1);
    EXPECT_LT(exact.fit.additivityDe00, 1e-3);
    EXPECT_LT(std::abs(exact.fit.additivityLuminancePercent), 1e-3);
    // Additive with 0.2 % noise: additive within the noise, whatever the draw.
    for (std::uint64_t seed = 1; seed <= 6; ++seed) {
        const DisplayModel m = fit(gogPanel(), 0.002, seed);
        EXPECT_TRUE(m.fit.additiveWithinNoise)
                << seed << ": dE00 " << m.fit.additivityDe00 << " vs " << m.fit.additivityNoiseDe00
                << ", " << m.fit.additivityLuminancePercent << " % +- "
                << m.fit.additivityLuminanceSigmaPercent;
        EXPECT_GT(m.fit.additivityLuminanceSigmaPercent, 0.1);
        EXPECT_LT(m.fit.additivityLuminanceSigmaPercent, 0.4);
    }
    // White 2 % darker than the channels' sum: seen, and not put down to noise.
    SyntheticDisplay cross = gogPanel();
    cross.interaction = 0.02;
    const DisplayModel m = fit(cross, 0.002, 3);
    EXPECT_FALSE(m.fit.additiveWithinNoise);
    EXPECT_NEAR(m.fit.additivityLuminancePercent, -2.0, 0.5);
}

} // namespace
} // namespace replica::pipeline::display
