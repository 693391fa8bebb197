// End to end from the sensed light (offline/display/colorchecker_study.h sensedStudy): an
// unimpaired instrument leaves only the display's own error; the data-sheet instrument costs a
// tenth of a CIEDE2000 on average; the classifier names every booth lamp.
#include <pipeline/base/data_dir.h>
#include <pipeline/colour/xyz.h>
#include <pipeline/offline/display/colorchecker_study.h>

#include <gtest/gtest.h>

#include "display_test_support.h"

namespace replica::pipeline::display {
namespace {

struct Bench {
    colour::Observer observer;
    std::vector<spectral::FineLight> lights;
    SensedSamples samples;
    spectral::AdaptiveEncoder encoder;
    DisplayInverse inverse;
};

const Bench& bench()
{
    static const Bench b = [] {
        auto obs = colour::loadCie1931(dataDir());
        auto lights = fineBoothLights(dataDir());
        auto samples = colorCheckerSamples(dataDir());
        auto encoder = spectral::AdaptiveEncoder::createDefault(dataDir());
        auto inverse = DisplayInverse::build(test::fittedSyntheticIps());
        REPLICA_ASSERT(obs && lights && samples && encoder && inverse, "bench data must load");
        return Bench{*obs, *lights, *samples, std::move(*encoder), std::move(*inverse)};
    }();
    return b;
}

Expected<std::vector<SensedLightStats>> run(const SensedStudyOptions& o)
{
    const Bench& b = bench();
    const DisplayModel model = b.inverse.model();
    auto panel = [model](const glm::dvec3& c) { return model.forward(c); };
    return sensedStudy(b.inverse, panel, b.observer, b.lights, b.samples, &b.encoder,
                       b.encoder.generalBasis(), o);
}

TEST(SensedStudy, AnUnimpairedInstrumentLeavesOnlyTheDisplay)
{
    SensedStudyOptions o;
    o.impairments = spectral::idealInstrument();
    o.impairments.fwhmNm = 1.3;
    o.wavelengthErrorMaxNm = 0.0;
    o.draws = 2;
    auto r = run(o);
    ASSERT_TRUE(r) << r.error().message;
    ASSERT_EQ(r->size(), 3u);
    for (const auto& l : *r) {
        // adaptive_k6 is exact for the light it is encoded for, and the light comes back exact.
        EXPECT_LT(l.render.max, 0.01) << l.light;
        // The display model inverted and dithered to 8 bits: a few hundredths at most in gamut.
        EXPECT_LT(l.panelInGamut.max, 0.05) << l.light;
        EXPECT_EQ(l.render.count, 2 * 24);
        EXPECT_EQ(l.panelInGamut.count + l.panelOutOfGamut.count, 2 * 24);
    }
    // Under tungsten the yellows are out of this panel's gamut (display study's finding).
    EXPECT_GE(r->back().panelOutOfGamut.count, 2 * 3);
}

TEST(SensedStudy, TheDataSheetInstrumentCostsLittleAndCorrectionsHelp)
{
    SensedStudyOptions o;
    o.draws = 3;
    auto plain = run(o);
    o.corrections.strayLight = true;
    o.corrections.wavelengthLines = true;
    o.corrections.scansAveraged = 5;
    auto fixed = run(o);
    o.mode = SensingMode::Classifier;
    auto classified = run(o);
    ASSERT_TRUE(plain && fixed && classified);
    double before = 0.0;
    double after = 0.0;
    for (std::size_t i = 0; i < plain->size(); ++i) {
        EXPECT_GT((*plain)[i].render.mean, 0.01) << (*plain)[i].light; // the impairments show
        EXPECT_LT((*plain)[i].render.mean, 0.3) << (*plain)[i].light;
        before += (*plain)[i].render.mean;
        after += (*fixed)[i].render.mean;
        EXPECT_EQ((*classified)[i].misclassified, 0) << (*classified)[i].light;
    }
    EXPECT_LT(after, 0.7 * before);
}

TEST(SensedStudy, RejectsAnEmptyStudy)
{
    SensedStudyOptions o;
    o.draws = 0;
    EXPECT_FALSE(run(o).has_value());
}

} // namespace
} // namespace replica::pipeline::display
