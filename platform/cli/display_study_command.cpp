// 'replica display study' and 'replica display flare': the ColorChecker through the whole chain
// (pipeline/offline/display/colorchecker_study.h) under the booth lights, as the paper's Table 1.
#include <functional>
#include <numbers>
#include <optional>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <nlohmann/json.hpp>

#include <pipeline/base/data_dir.h>
#include <pipeline/colour/channel_basis.h>
#include <pipeline/offline/display/colorchecker_study.h>
#include <pipeline/offline/display/synthetic_display.h>
#include <pipeline/spectral/reference_sets.h>
#include <pipeline/spectral/representation_catalogue.h>
#include <platform/cli/commands.h>
#include <platform/cli/display_command.h>
#include <platform/cli/sensed_report.h>
#include <platform/logging.h>

namespace replica::platform {
namespace {

namespace pd = pipeline::display;

const char* shortClass(pd::GamutClass c)
{
    switch (c) {
    case pd::GamutClass::InGamut:
        return "in";
    case pd::GamutClass::Chroma:
        return "chroma";
    case pd::GamutClass::OverPeak:
        return "above peak";
    case pd::GamutClass::BelowBlack:
        return "below black";
    }
    return "?";
}

nlohmann::json statsJson(const pd::ErrorStats& s)
{
    return {{"n", s.count}, {"mean", s.mean}, {"std", s.std}, {"p90", s.p90}, {"max", s.max}};
}

std::string statsText(const pd::ErrorStats& s)
{
    return fmt::format("{:5.2f} {:5.2f} {:5.2f} {:5.2f}", s.mean, s.std, s.p90, s.max);
}

// Everything the study commands share: the profile, the panel a meter reads, the channel basis.
struct StudySetup {
    std::optional<pd::DisplayInverse> inverse;
    std::function<glm::dvec3(const glm::dvec3&)> panel;
    pd::StudyOptions options;
    std::shared_ptr<pipeline::spectral::Representation> paperSix; // the paper's construction
};

std::optional<StudySetup> studySetup(const DisplayOptions& o)
{
    auto log = logger("replica");
    StudySetup s;
    s.inverse = loadDisplayInverse(o.profile.empty() ? defaultDisplayProfile() : o.profile);
    if (!s.inverse) {
        return std::nullopt;
    }
    if (o.panel == "truth") {
        if (!s.inverse->model().synthetic) {
            log->error(
                    "--panel truth: profile '{}' is of a real panel; only a synthetic profile has "
                    "a known ground truth",
                    s.inverse->model().name);
            return std::nullopt;
        }
        const pd::SyntheticDisplay truth = pd::wideIpsGroundTruth();
        s.panel = [truth](const glm::dvec3& c) { return truth.forward(c); };
    } else {
        const pd::DisplayModel model = s.inverse->model();
        s.panel = [model](const glm::dvec3& c) { return model.forward(c); };
    }
    if (o.basis == "box6") {
        s.options.basis = pipeline::colour::boxBasis();
    } else {
        auto basis =
                pipeline::colour::loadChannelBasis(dataDir() / "channels" / (o.basis + ".csv"));
        if (!basis) {
            log->error("{}", basis.error().message);
            return std::nullopt;
        }
        s.options.basis = std::move(*basis);
    }
    {
        auto obs = pipeline::colour::loadCie1931(dataDir());
        auto d65 = obs ? pipeline::spectral::loadCieIlluminant(dataDir(), "D65")
                       : Expected<pipeline::colour::Spectrum>(tl::unexpected(obs.error()));
        if (!obs || !d65) {
            log->error("{}", !obs ? obs.error().message : d65.error().message);
            return std::nullopt;
        }
        auto paper = pipeline::spectral::makeRepresentation(dataDir(), *obs, *d65, "paper6");
        if (!paper) {
            log->error("{}", paper.error().message);
            return std::nullopt;
        }
        s.paperSix = std::move(*paper);
        s.options.paperSix = s.paperSix.get();
    }
    s.options.illuminanceLux = o.lux;
    s.options.flare = o.flare == "dark"     ? pd::FlareHandling::Dark
                      : o.flare == "ignore" ? pd::FlareHandling::InBoothIgnore
                                            : pd::FlareHandling::InBoothSubtract;
    return s;
}

// The sensed-light study (--sensed): the spectrometer's reading of each booth light through the
// chain.
int sensedStudyMain(const DisplayOptions& o, const StudySetup& setup)
{
    auto lights = pd::fineBoothLights(dataDir());
    auto samples = pd::colorCheckerSamples(dataDir());
    if (!lights || !samples) {
        logger("replica")->error("{}", !lights ? lights.error().message : samples.error().message);
        return kExitFailure;
    }
    SensedReportOptions so = o.sensed;
    so.json = o.json;
    return sensedReport(*setup.inverse, setup.panel, *lights, *samples, o.lux, setup.options.flare,
                        so);
}

void printStudyJson(const DisplayOptions& o,
                    const StudySetup& setup,
                    const std::vector<pd::LightResult>& results)
{
    nlohmann::json lights = nlohmann::json::array();
    for (const auto& lr : results) {
        nlohmann::json patches = nlohmann::json::array();
        for (const auto& p : lr.patches) {
            patches.push_back({{"name", p.name},
                               {"gamut", shortClass(p.gamutClass)},
                               {"six_channel_de00", p.sixChannelDe00},
                               {"mapped_de00", p.mappedDe00},
                               {"clipped_de00", p.clippedDe00},
                               {"mapped_absolute_de00", p.mappedAbsoluteDe00},
                               {"clipped_absolute_de00", p.clippedAbsoluteDe00},
                               {"paper6_de00", p.paperSixDe00},
                               {"paper6_mapped_de00", p.paperSixMappedDe00}});
        }
        lights.push_back({{"light", lr.light},
                          {"six_channel", statsJson(lr.sixChannel)},
                          {"paper6", statsJson(lr.paperSix)},
                          {"screen_paper6_mapped", statsJson(lr.paperSixMapped)},
                          {"screen_paper6_mapped_in_gamut", statsJson(lr.paperSixMappedInGamut)},
                          {"screen_mapped", statsJson(lr.mapped)},
                          {"screen_clipped", statsJson(lr.clipped)},
                          {"screen_mapped_in_gamut", statsJson(lr.mappedInGamut)},
                          {"screen_mapped_absolute", statsJson(lr.mappedAbsolute)},
                          {"screen_clipped_absolute", statsJson(lr.clippedAbsolute)},
                          {"out_of_gamut", lr.outOfGamut},
                          {"patches", patches}});
    }
    fmt::print("{}\n", nlohmann::json{{"profile", setup.inverse->model().name},
                                      {"panel", o.panel},
                                      {"basis", setup.options.basis.name},
                                      {"lux", o.lux},
                                      {"flare", o.flare},
                                      {"lights", lights}}
                               .dump(1));
}

// Per light: the six-channel and screen workflows' dE00 statistics, and over the in-gamut
// patches where some are out of gamut.
void printStudyTable(const DisplayOptions& o,
                     const StudySetup& setup,
                     const std::vector<pd::LightResult>& results)
{
    fmt::print("ColorChecker: spectral -> {} channels -> XYZ -> inverse display -> 8-bit counts "
               "(dithered) -> {}\n",
               setup.options.basis.name,
               o.panel == "truth" ? "synthetic ground-truth panel" : "profile forward model");
    fmt::print("profile {}, {} lux on the screen, front-surface flare: {}; CIEDE2000 after CAT02 "
               "to D65, each workflow relative to its own white patch (as the paper)\n\n",
               setup.inverse->model().name, o.lux, o.flare);
    fmt::print("{:<26} {:>3}  {:^23}  {:^23}  {:^23}  {:^23}  {:^23}\n", "", "",
               "six-channel: paper6", fmt::format("six-channel: {}", setup.options.basis.name),
               "screen via paper6, map", "screen, hue-keeping map", "screen, per-channel clip");
    fmt::print("{:<26} {:>3}  {:^23}  {:^23}  {:^23}  {:^23}  {:^23}\n", "light", "n",
               "mean   std  90th   max", "mean   std  90th   max", "mean   std  90th   max",
               "mean   std  90th   max", "mean   std  90th   max");
    for (const auto& lr : results) {
        fmt::print("{:<26} {:>3}  {}  {}  {}  {}  {}\n", lr.light, lr.sixChannel.count,
                   statsText(lr.paperSix), statsText(lr.sixChannel), statsText(lr.paperSixMapped),
                   statsText(lr.mapped), statsText(lr.clipped));
    }
    for (const auto& lr : results) {
        if (lr.outOfGamut.empty()) {
            continue;
        }
        std::vector<double> six;
        std::vector<double> paper;
        std::vector<double> clipped;
        for (const auto& p : lr.patches) {
            if (p.gamutClass == pd::GamutClass::InGamut) {
                six.push_back(p.sixChannelDe00);
                paper.push_back(p.paperSixDe00);
                clipped.push_back(p.clippedDe00);
            }
        }
        fmt::print("{:<26} {:>3}  {}  {}  {}  {}  {}\n", fmt::format("  in-gamut, {}", lr.light),
                   lr.mappedInGamut.count, statsText(pd::errorStats(paper)),
                   statsText(pd::errorStats(six)), statsText(lr.paperSixMappedInGamut),
                   statsText(lr.mappedInGamut), statsText(pd::errorStats(clipped)));
    }
}

// Without the white-patch normalisation, the patches out of gamut, and what the figures compare
// with.
void printStudyNotes(const DisplayOptions& o, const std::vector<pd::LightResult>& results)
{
    fmt::print("\nwithout the white-patch normalisation (vs the perfect diffuser under each "
               "light):\n");
    fmt::print("{:<26} {:>3}  {:^23}  {:^23}\n", "light", "n", "screen, hue-keeping map",
               "screen, per-channel clip");
    for (const auto& lr : results) {
        fmt::print("{:<26} {:>3}  {}  {}\n", lr.light, lr.mappedAbsolute.count,
                   statsText(lr.mappedAbsolute), statsText(lr.clippedAbsolute));
    }
    fmt::print("\n");
    for (const auto& lr : results) {
        std::vector<std::string> named;
        for (const auto& p : lr.patches) {
            if (p.gamutClass != pd::GamutClass::InGamut) {
                named.push_back(fmt::format("{} ({}; dE00 mapped {:.1f}, clipped {:.1f}; absolute "
                                            "{:.1f}, {:.1f})",
                                            p.name, shortClass(p.gamutClass), p.mappedDe00,
                                            p.clippedDe00, p.mappedAbsoluteDe00,
                                            p.clippedAbsoluteDe00));
            }
        }
        fmt::print("out of gamut under {}: {}\n", lr.light,
                   named.empty() ? std::string("none") : fmt::format("{}", fmt::join(named, ", ")));
    }
    fmt::print("\n{}\n",
               o.panel == "truth"
                       ? "panel: the synthetic panel's ground truth (0.5 % channel interaction), "
                         "shown through a profile fitted from its readings by a simulated meter "
                         "with 0.2 % noise: a SYNTHETIC panel measured with noise, not a real one"
                       : "panel: the profile's own forward model (no measurement: the display "
                         "stage's floor)");
    fmt::print(
            "paper6: the paper's construction (light and reflectance each projected onto six "
            "channels, multiplied, [6 x 3] to XYZ), fitted by 'replica spectral fit'; paper "
            "Table 1 six-channel: D65 0.4 0.3 0.8 1.7; D50 0.4 0.3 0.7 1.5; A 0.8 0.4 1.3 2.1\n");
    fmt::print("paper (EIZO RX220, measured screen output): D65 0.8 0.4 1.4 1.6; D50 0.7 0.4 1.1 "
               "1.8; A 3.8 4.2 11.0 14.0; A in-gamut (18) 1.8 1.6 5.0 5.9\n");
}

} // namespace

int displayStudyMain(const DisplayOptions& o)
{
    auto setup = studySetup(o);
    if (!setup) {
        return kExitFailure;
    }
    if (o.sensed.sensed) {
        return sensedStudyMain(o, *setup);
    }
    auto results = pd::colorCheckerStudy(*setup->inverse, setup->panel, dataDir(), setup->options);
    if (!results) {
        logger("replica")->error("{}", results.error().message);
        return kExitFailure;
    }
    if (o.json) {
        printStudyJson(o, *setup, *results);
        return kExitOk;
    }
    printStudyTable(o, *setup, *results);
    printStudyNotes(o, *results);
    return kExitOk;
}

// How much the screen's own reflection of the booth light matters for dark colours: the study
// with the reflection left in (what a viewer sees without correction) and subtracted.
int displayFlareMain(const DisplayOptions& o)
{
    DisplayOptions ignore = o;
    ignore.flare = "ignore";
    DisplayOptions subtract = o;
    subtract.flare = "subtract";
    // One setup's error is the other's too: say it once.
    auto a = studySetup(ignore);
    if (!a) {
        return kExitFailure;
    }
    auto b = studySetup(subtract);
    if (!b) {
        return kExitFailure;
    }
    auto left = pd::colorCheckerStudy(*a->inverse, a->panel, dataDir(), a->options);
    auto corrected = pd::colorCheckerStudy(*b->inverse, b->panel, dataDir(), b->options);
    if (!left || !corrected) {
        logger("replica")->error("{}", (!left ? left : corrected).error().message);
        return kExitFailure;
    }
    const double rho = a->inverse->model().frontSurfaceReflectance;
    fmt::print("front-surface reflection rho_d = {} at {} lux: {:.3f} cd/m^2 added to every "
               "pixel; profile {} ({})\n",
               rho, o.lux, rho * o.lux / std::numbers::pi, a->inverse->model().name,
               a->inverse->model().condition == pd::MeasurementCondition::LitBooth
                       ? "measured in the lit booth: its black already holds the reflection"
                       : "measured in the dark");
    fmt::print("CIEDE2000 against the perfect diffuser under each light (no white-patch "
               "normalisation), hue-keeping map; Y is the surface's luminance\n");
    fmt::print("{:<22} {:<14} {:>10} {:>14} {:>14}\n", "light", "patch", "Y cd/m^2", "dE00 left in",
               "dE00 removed");
    const std::vector<std::string> dark{"black_2",   "neutral_3.5",   "neutral_5",
                                        "dark_skin", "purplish_blue", "neutral_8"};
    for (std::size_t l = 0; l < left->size(); ++l) {
        for (const auto& name : dark) {
            for (std::size_t p = 0; p < (*left)[l].patches.size(); ++p) {
                const auto& pl = (*left)[l].patches[p];
                const auto& pc = (*corrected)[l].patches[p];
                if (pl.name == name) {
                    fmt::print("{:<22} {:<14} {:>10.3f} {:>14.2f} {:>14.2f}\n", (*left)[l].light,
                               name, pl.targetXyz.y, pl.mappedAbsoluteDe00, pc.mappedAbsoluteDe00);
                }
            }
        }
        fmt::print("{:<22} {:<14} {:>10} {:>14.2f} {:>14.2f}\n", (*left)[l].light, "all 24 (mean)",
                   "", (*left)[l].mappedAbsolute.mean, (*corrected)[l].mappedAbsolute.mean);
    }
    return kExitOk;
}

} // namespace replica::platform
