// 'replica display': fit a display profile from measurements, run its forward and inverse model
// for scripts and field checks, and write the synthetic measurement set the shipped profile uses.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <numbers>
#include <optional>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <nlohmann/json.hpp>

#include <pipeline/base/data_dir.h>
#include <pipeline/colour/channel_basis.h>
#include <pipeline/display/cgats.h>
#include <pipeline/display/colorchecker_study.h>
#include <pipeline/display/display_fit.h>
#include <pipeline/display/display_inverse.h>
#include <pipeline/display/display_profile.h>
#include <pipeline/display/icc_profile.h>
#include <pipeline/display/synthetic_display.h>
#include <pipeline/display/viewing_angle_csv.h>
#include <pipeline/spectral/reference_sets.h>
#include <pipeline/spectral/representation_catalogue.h>
#include <platform/cli/commands.h>
#include <platform/cli/display_patches.h>
#include <platform/cli/sensed_report.h>
#include <platform/logging.h>

namespace replica::platform {
namespace {

namespace pd = pipeline::display;

struct DisplayOptions {
    std::string measurements;
    std::string profile;
    std::string out;
    std::string name;
    std::string measuredIn = "dark";
    std::string triple;
    std::string viewingTable;
    int bits = 0;
    bool synthetic = false;
    bool json = false;
    bool clip = false;
    std::uint64_t seed = 1;
    double lux = 2000.0;
    std::string flare = "subtract";
    std::string panel = "model";
    std::string basis = "replica_k6";
    std::string tone = "robust";
    std::string icc;
    SensedReportOptions sensed;
};

// The shipped profile, where a command takes the profile as an option.
std::string defaultProfile()
{
    return (dataDir() / "displays" / "wide-ips-synthetic.json").string();
}

// "a,b,c" -> three finite numbers.
std::optional<glm::dvec3> parseTriple(const std::string& s)
{
    double a = 0.0;
    double b = 0.0;
    double c = 0.0;
    char extra = 0;
    if (std::sscanf(s.c_str(), " %lf , %lf , %lf %c", &a, &b, &c, &extra) != 3 ||
        !std::isfinite(a) || !std::isfinite(b) || !std::isfinite(c)) {
        return std::nullopt;
    }
    return glm::dvec3{a, b, c};
}

const char* gamutName(pd::GamutClass c)
{
    switch (c) {
    case pd::GamutClass::InGamut:
        return "in gamut";
    case pd::GamutClass::Chroma:
        return "out of gamut (chroma; mapped towards the neutral of the same luminance)";
    case pd::GamutClass::OverPeak:
        return "out of gamut (above peak white; scaled to peak)";
    case pd::GamutClass::BelowBlack:
        return "out of gamut (at or below display black; shown as black)";
    }
    return "?";
}

int fitMain(const DisplayOptions& o)
{
    auto log = logger("replica");
    if (o.measuredIn != "dark" && o.measuredIn != "lit-booth") {
        log->error("--measured-in {}: expected 'dark' or 'lit-booth'", o.measuredIn);
        return kExitUsage;
    }
    auto set = pd::loadMeasurements(o.measurements, o.bits);
    if (!set) {
        log->error("{}", set.error().message);
        return kExitFailure;
    }
    // The outputs are checked before the fit, not after it: an unwritable --out or --icc fails at
    // once, and a file that did not exist is not left behind.
    for (const std::string& path : {o.out, o.icc}) {
        if (path.empty()) {
            continue;
        }
        std::error_code ec;
        const bool existed = std::filesystem::exists(path, ec);
        if (existed && !std::filesystem::is_regular_file(path, ec)) {
            log->error("{}: not a regular file; give a file path to write", path);
            return kExitFailure;
        }
        const bool writable =
                static_cast<bool>(std::ofstream(path, std::ios::binary | std::ios::app));
        if (!existed) {
            std::filesystem::remove(path, ec);
        }
        if (!writable) {
            log->error("{}: cannot write here (check the folder exists and is writable)", path);
            return kExitFailure;
        }
    }
    pd::FitOptions fo;
    fo.name = o.name.empty() ? std::filesystem::path(o.out).stem().string() : o.name;
    fo.synthetic = o.synthetic;
    fo.toneMethod = o.tone == "interpolate" ? pd::ToneMethod::Interpolate : pd::ToneMethod::Robust;
    fo.condition = o.measuredIn == "dark" ? pd::MeasurementCondition::Dark
                                          : pd::MeasurementCondition::LitBooth;
    fo.description = fmt::format("fitted by 'replica display fit' from {} ({} rows, {}-bit){}",
                                 std::filesystem::path(o.measurements).filename().string(),
                                 set->rows.size(), set->bitDepth,
                                 o.synthetic ? "; SYNTHETIC measurements, not a real panel" : "");
    auto model = pd::fitDisplay(*set, fo);
    if (!model) {
        log->error("{}", model.error().message);
        return kExitFailure;
    }
    if (!o.viewingTable.empty()) {
        auto table = pd::loadViewingAngleCsv(o.viewingTable);
        if (!table) {
            log->error("{}", table.error().message);
            return kExitFailure;
        }
        model->viewing = std::move(*table);
    } else if (o.synthetic) {
        // The synthetic panel's viewing-angle table travels with its profile.
        model->viewing = pd::wideIpsViewingAngles();
    }
    if (auto ok = pd::saveProfile(*model, o.out); !ok) {
        log->error("{}", ok.error().message);
        return kExitFailure;
    }
    if (!o.icc.empty()) {
        auto icc = pd::writeIccProfile(*model, o.icc);
        if (!icc) {
            log->error("{}", icc.error().message);
            return kExitFailure;
        }
        if (icc->blackClipped) {
            log->warn("{}: black lies outside the primaries' triangle; the ICC profile's black is "
                      "the nearest the matrix/TRC form holds",
                      o.icc);
        }
        if (icc->crosstalkOmitted) {
            log->warn("{}: the fit's crosstalk term (white {:.2f} % from R+G+B) is left out: a "
                      "matrix/TRC profile holds only the additive part; the JSON profile has it",
                      o.icc,
                      100.0 *
                              (model->forward(glm::dvec3(model->maxCount())).y -
                               model->whiteXyz().y) /
                              model->whiteXyz().y);
        }
    }
    const auto& f = model->fit;
    if (o.json) {
        fmt::print("{}\n",
                   nlohmann::json{{"profile", o.out},
                                  {"held_out_colours", f.heldOutColours},
                                  {"held_out_mean_de00", f.heldOutMeanDe00},
                                  {"held_out_p90_de00", f.heldOutP90De00},
                                  {"held_out_max_de00", f.heldOutMaxDe00},
                                  {"additivity_de00", f.additivityDe00},
                                  {"additivity_luminance_percent", f.additivityLuminancePercent},
                                  {"additivity_noise_de00", f.additivityNoiseDe00},
                                  {"additivity_luminance_sigma_percent",
                                   f.additivityLuminanceSigmaPercent},
                                  {"additive_within_noise", f.additiveWithinNoise},
                                  {"noise_percent", f.noisePercent},
                                  {"held_out_noise_mean_de00", f.heldOutNoiseMeanDe00},
                                  {"tone_shape", f.toneShape},
                                  {"inverse_counts_rms", f.inverseCountsRms},
                                  {"inverse_counts_max", f.inverseCountsMax},
                                  {"gamut_edge_tolerance", model->gamutEdgeTolerance},
                                  {"crosstalk_model", f.crosstalkModel},
                                  {"crosstalk_gain_de00", f.crosstalkGainDe00}}
                           .dump());
    } else {
        // The model's white (with a crosstalk term, below black + R + G + B).
        const glm::dvec3 w = model->forward(glm::dvec3(model->maxCount()));
        fmt::print("profile: {}{}\n", o.out,
                   o.icc.empty() ? std::string() : fmt::format(" (and ICC v4: {})", o.icc));
        fmt::print("white {:.1f} cd/m^2, black {:.3f} cd/m^2, {}-bit\n", w.y, model->blackXyz.y,
                   model->bitDepth);
        fmt::print("held-out dE00 over {} colours: mean {:.3f}, 90th {:.3f}, max {:.3f} "
                   "(direct primaries: mean {:.3f}; training mean {:.3f})\n",
                   f.heldOutColours, f.heldOutMeanDe00, f.heldOutP90De00, f.heldOutMaxDe00,
                   f.directPrimariesHeldOutMeanDe00, f.trainingMeanDe00);
        if (f.noisePercent >= 0.0) {
            fmt::print(
                    "meter noise (from the ramps' residuals): {:.3f}% per XYZ component; held-out "
                    "readings' own noise alone gives mean dE00 {:.3f}\n",
                    f.noisePercent, f.heldOutNoiseMeanDe00);
            fmt::print("tone curves (cross-validated): R {} G {} B {}; inverse's expected error "
                       "(1 sigma) in counts: rms {:.2f} {:.2f} {:.2f}, max {:.2f} {:.2f} {:.2f} "
                       "(where the light is at least 0.1% of full drive)\n",
                       f.toneShape[0], f.toneShape[1], f.toneShape[2], f.inverseCountsRms[0],
                       f.inverseCountsRms[1], f.inverseCountsRms[2], f.inverseCountsMax[0],
                       f.inverseCountsMax[1], f.inverseCountsMax[2]);
            fmt::print("gamut edge tolerance: {:.4f} in r (4 sigma of the fit at the gamut's "
                       "corners; colours within it of the gamut are clamped per channel, not "
                       "gamut-mapped)\n",
                       model->gamutEdgeTolerance);
            if (model->hasCrosstalk()) {
                const glm::dmat3& c = model->crosstalk;
                fmt::print("crosstalk ({}; one-parameter coefficient {:.1f} standard errors from "
                           "zero, cross-validated gain dE00 {:.4f}): r + C (rg, gb, br), "
                           "C rows R {:+.5f} {:+.5f} {:+.5f} G {:+.5f} {:+.5f} {:+.5f} B {:+.5f} "
                           "{:+.5f} {:+.5f}; white {:+.2f}% from black + R + G + B\n",
                           f.crosstalkModel, f.crosstalkZ, f.crosstalkGainDe00, c[0][0], c[1][0],
                           c[2][0], c[0][1], c[1][1], c[2][1], c[0][2], c[1][2], c[2][2],
                           100.0 * (w.y - model->whiteXyz().y) / model->whiteXyz().y);
            } else if (!f.crosstalkModel.empty()) {
                fmt::print("crosstalk: none (one-parameter coefficient {:.1f} standard errors from "
                           "zero, needs 3; cross-validated gain dE00 {:.4f}, needs 0.001)\n",
                           f.crosstalkZ, f.crosstalkGainDe00);
            }
        }
        if (f.additivityDe00 >= 0.0 && f.additivityNoiseDe00 >= 0.0) {
            fmt::print("additivity: white vs black + R + G + B dE00 {:.3f} (the noise alone gives "
                       "up to {:.3f}, 99.9th percentile), luminance {:+.2f}% +- {:.2f}% (1 sigma): "
                       "{}\n",
                       f.additivityDe00, f.additivityNoiseDe00, f.additivityLuminancePercent,
                       f.additivityLuminanceSigmaPercent,
                       f.additiveWithinNoise
                               ? "additive within the noise"
                               : "NOT additive: channel interaction beyond the noise");
        } else if (f.additivityDe00 >= 0.0) {
            fmt::print("additivity: white vs R+G+B dE00 {:.3f}, luminance {:+.2f}%\n",
                       f.additivityDe00, f.additivityLuminancePercent);
        }
        fmt::print("primary chromaticity drift along ramps (max |dxy|): R {:.4f} G {:.4f} B "
                   "{:.4f}; ramp points pooled for monotonicity: {}\n",
                   f.chromaticityDrift[0], f.chromaticityDrift[1], f.chromaticityDrift[2],
                   f.monotonicCorrections);
    }
    return kExitOk;
}

std::optional<pd::DisplayInverse> loadInverse(const std::string& path)
{
    auto model = pd::loadProfile(path);
    if (!model) {
        logger("replica")->error("{}", model.error().message);
        return std::nullopt;
    }
    auto inv = pd::DisplayInverse::build(*model);
    if (!inv) {
        logger("replica")->error("{}: {}", path, inv.error().message);
        return std::nullopt;
    }
    return std::move(*inv);
}

int inverseMain(const DisplayOptions& o)
{
    const auto xyz = parseTriple(o.triple);
    if (!xyz) {
        logger("replica")->error("--xyz {}: expected three numbers X,Y,Z in cd/m^2", o.triple);
        return kExitUsage;
    }
    const auto inv = loadInverse(o.profile);
    if (!inv) {
        return kExitFailure;
    }
    const auto r = inv->invert(*xyz, o.clip ? pd::GamutMode::Clip : pd::GamutMode::HueKeeping,
                               pd::ToneInverse::Exact);
    if (o.json) {
        fmt::print("{}\n", nlohmann::json{{"rgb", {r.counts.x, r.counts.y, r.counts.z}},
                                          {"in_gamut", r.inGamut()}}
                                   .dump());
    } else {
        fmt::print("rgb {:.4f},{:.4f},{:.4f} ({})\n", r.counts.x, r.counts.y, r.counts.z,
                   gamutName(r.gamutClass));
    }
    return kExitOk;
}

int forwardMain(const DisplayOptions& o)
{
    const auto rgb = parseTriple(o.triple);
    if (!rgb) {
        logger("replica")->error("--rgb {}: expected three counts R,G,B", o.triple);
        return kExitUsage;
    }
    auto model = pd::loadProfile(o.profile);
    if (!model) {
        logger("replica")->error("{}", model.error().message);
        return kExitFailure;
    }
    for (int c = 0; c < 3; ++c) {
        if ((*rgb)[c] < 0.0 || (*rgb)[c] > model->maxCount()) {
            logger("replica")->error("--rgb {}: counts must lie in [0, {}] for this {}-bit "
                                     "profile",
                                     o.triple, model->maxCount(), model->bitDepth);
            return kExitUsage;
        }
    }
    const glm::dvec3 xyz = model->forward(*rgb);
    if (o.json) {
        fmt::print("{}\n", nlohmann::json{{"xyz", {xyz.x, xyz.y, xyz.z}}}.dump());
    } else {
        fmt::print("xyz {:.4f},{:.4f},{:.4f} cd/m^2\n", xyz.x, xyz.y, xyz.z);
    }
    return kExitOk;
}

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
    s.inverse = loadInverse(o.profile.empty() ? defaultProfile() : o.profile);
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

int studyMain(const DisplayOptions& o)
{
    auto setup = studySetup(o);
    if (!setup) {
        return kExitFailure;
    }
    if (o.sensed.sensed) {
        auto lights = pd::fineBoothLights(dataDir());
        auto samples = pd::colorCheckerSamples(dataDir());
        if (!lights || !samples) {
            logger("replica")->error("{}",
                                     !lights ? lights.error().message : samples.error().message);
            return kExitFailure;
        }
        SensedReportOptions so = o.sensed;
        so.json = o.json;
        return sensedReport(*setup->inverse, setup->panel, *lights, *samples, o.lux,
                            setup->options.flare, so);
    }
    auto results = pd::colorCheckerStudy(*setup->inverse, setup->panel, dataDir(), setup->options);
    if (!results) {
        logger("replica")->error("{}", results.error().message);
        return kExitFailure;
    }
    if (o.json) {
        nlohmann::json lights = nlohmann::json::array();
        for (const auto& lr : *results) {
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
            lights.push_back(
                    {{"light", lr.light},
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
        fmt::print("{}\n", nlohmann::json{{"profile", setup->inverse->model().name},
                                          {"panel", o.panel},
                                          {"basis", setup->options.basis.name},
                                          {"lux", o.lux},
                                          {"flare", o.flare},
                                          {"lights", lights}}
                                   .dump(1));
        return kExitOk;
    }
    fmt::print("ColorChecker: spectral -> {} channels -> XYZ -> inverse display -> 8-bit counts "
               "(dithered) -> {}\n",
               setup->options.basis.name,
               o.panel == "truth" ? "synthetic ground-truth panel" : "profile forward model");
    fmt::print("profile {}, {} lux on the screen, front-surface flare: {}; CIEDE2000 after CAT02 "
               "to D65, each workflow relative to its own white patch (as the paper)\n\n",
               setup->inverse->model().name, o.lux, o.flare);
    fmt::print("{:<26} {:>3}  {:^23}  {:^23}  {:^23}  {:^23}  {:^23}\n", "", "",
               "six-channel: paper6", fmt::format("six-channel: {}", setup->options.basis.name),
               "screen via paper6, map", "screen, hue-keeping map", "screen, per-channel clip");
    fmt::print("{:<26} {:>3}  {:^23}  {:^23}  {:^23}  {:^23}  {:^23}\n", "light", "n",
               "mean   std  90th   max", "mean   std  90th   max", "mean   std  90th   max",
               "mean   std  90th   max", "mean   std  90th   max");
    for (const auto& lr : *results) {
        fmt::print("{:<26} {:>3}  {}  {}  {}  {}  {}\n", lr.light, lr.sixChannel.count,
                   statsText(lr.paperSix), statsText(lr.sixChannel), statsText(lr.paperSixMapped),
                   statsText(lr.mapped), statsText(lr.clipped));
    }
    for (const auto& lr : *results) {
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
    fmt::print("\nwithout the white-patch normalisation (vs the perfect diffuser under each "
               "light):\n");
    fmt::print("{:<26} {:>3}  {:^23}  {:^23}\n", "light", "n", "screen, hue-keeping map",
               "screen, per-channel clip");
    for (const auto& lr : *results) {
        fmt::print("{:<26} {:>3}  {}  {}\n", lr.light, lr.mappedAbsolute.count,
                   statsText(lr.mappedAbsolute), statsText(lr.clippedAbsolute));
    }
    fmt::print("\n");
    for (const auto& lr : *results) {
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
    return kExitOk;
}

// How much the screen's own reflection of the booth light matters for dark colours: the study
// with the reflection left in (what a viewer sees without correction) and subtracted.
int flareMain(const DisplayOptions& o)
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

int synthMain(const DisplayOptions& o)
{
    const auto rows = pd::syntheticMeasurements(pd::wideIpsGroundTruth(), pd::MeterNoise{}, o.seed);
    const std::string comment = fmt::format(
            "SYNTHETIC display measurements (not a real panel), written by 'replica display synth "
            "--seed {}':\n"
            "the ground-truth wide-luminance IPS of pipeline/display/synthetic_display.cpp read "
            "through\n"
            "a simulated meter with 0.2 % + 0.005 cd/m^2 noise. Counts 8-bit; XYZ in cd/m^2.",
            o.seed);
    std::ofstream f(o.out, std::ios::binary | std::ios::trunc);
    f << pd::measurementCsv(rows, comment);
    f.close();
    if (!f) {
        logger("replica")->error("{}: cannot write the measurement file", o.out);
        return kExitFailure;
    }
    fmt::print("measurements: {} ({} rows)\n", o.out, rows.size());
    return kExitOk;
}

} // namespace

void registerDisplayCommand(CLI::App& app, int& exitCode)
{
    auto* display = app.add_subcommand(
            "display",
            "display characterisation: fit a profile, run its forward and inverse model");
    display->require_subcommand(1);

    auto fit = std::make_shared<DisplayOptions>();
    auto* fitCmd = display->add_subcommand(
            "fit", "fit a display profile to measurements: MEAS.csv (columns R,G,B,X,Y,Z: counts "
                   "at the panel's bit depth, XYZ in cd/m^2) or an ArgyllCMS MEAS.ti3");
    fitCmd->add_option("measurements", fit->measurements,
                       "measurements: CSV R,G,B,X,Y,Z, or an ArgyllCMS .ti3 (dispread's readings)")
            ->required();
    fitCmd->add_option("--out", fit->out, "profile to write (JSON)")->required();
    fitCmd->add_option("--name", fit->name, "profile name (default: the output file's stem)");
    fitCmd->add_option("--bits", fit->bits,
                       "panel bit depth (default: from the largest count; 8 for a .ti3)")
            ->check(CLI::Range(1, 16));
    fitCmd->add_option("--measured-in", fit->measuredIn,
                       "dark, or lit-booth (the black then already holds the screen's reflection "
                       "of the booth light, which is then not subtracted again)")
            ->capture_default_str();
    fitCmd->add_flag("--synthetic", fit->synthetic,
                     "mark the profile as built from synthetic measurements (and attach the "
                     "synthetic panel's viewing-angle table)");
    fitCmd->add_option("--viewing-table", fit->viewingTable,
                       "full white measured off axis: CSV angle_deg,X,Y,Z (first row 0 deg); "
                       "without it the profile has no viewing-angle compensation");
    fitCmd->add_option("--tone", fit->tone,
                       "tone curves: robust (average the meter's noise: GOG, GOGO or a smoothing "
                       "spline, chosen by cross-validation) or interpolate (through every ramp "
                       "reading; the shipped synthetic profile)")
            ->check(CLI::IsMember({"robust", "interpolate"}))
            ->capture_default_str();
    fitCmd->add_option("--icc", fit->icc,
                       "also write the profile as an ICC v4 display profile (matrix/TRC, D50 PCS, "
                       "white's luminance in the lumi tag)");
    fitCmd->add_flag("--json", fit->json, "print the fit report as JSON");
    fitCmd->callback([fit, &exitCode] { exitCode = fitMain(*fit); });

    auto inv = std::make_shared<DisplayOptions>();
    auto* invCmd = display->add_subcommand(
            "inverse", "counts (real-valued, before quantisation) for an absolute XYZ");
    invCmd->add_option("profile", inv->profile, "display profile (JSON)")->required();
    invCmd->add_option("--xyz", inv->triple, "X,Y,Z in cd/m^2")->required();
    invCmd->add_flag("--clip", inv->clip,
                     "clip each channel instead of the hue-keeping gamut mapping");
    invCmd->add_flag("--json", inv->json, "print {\"rgb\": [R, G, B], \"in_gamut\": bool}");
    invCmd->callback([inv, &exitCode] { exitCode = inverseMain(*inv); });

    auto fwd = std::make_shared<DisplayOptions>();
    auto* fwdCmd = display->add_subcommand("forward", "absolute XYZ (cd/m^2) the panel emits for "
                                                      "counts R,G,B (real values allowed)");
    fwdCmd->add_option("profile", fwd->profile, "display profile (JSON)")->required();
    fwdCmd->add_option("--rgb", fwd->triple, "R,G,B counts")->required();
    fwdCmd->add_flag("--json", fwd->json, "print {\"xyz\": [X, Y, Z]}");
    fwdCmd->callback([fwd, &exitCode] { exitCode = forwardMain(*fwd); });

    auto addStudyOptions = [](CLI::App* cmd, DisplayOptions& opts) {
        cmd->add_option("profile", opts.profile,
                        "display profile (default: data/displays/wide-ips-synthetic.json)");
        cmd->add_option("--lux", opts.lux, "illuminance on the screen (lux)")
                ->check(CLI::Range(1.0, 1e5))
                ->capture_default_str();
        cmd->add_option("--panel", opts.panel,
                        "what the meter reads: model (the profile's forward model) or truth (the "
                        "synthetic panel's ground truth)")
                ->check(CLI::IsMember({"model", "truth"}))
                ->capture_default_str();
        cmd->add_option("--basis", opts.basis,
                        "channel basis: replica_k6 (the appliance's), general_k6, pca6, paper6 "
                        "or box6")
                ->capture_default_str();
    };
    auto study = std::make_shared<DisplayOptions>();
    auto* studyCmd = display->add_subcommand(
            "study", "the paper's Table 1 (right half): the ColorChecker through the whole chain "
                     "under the booth lights A, F8 and F7, with and without gamut mapping");
    addStudyOptions(studyCmd, *study);
    studyCmd->add_option("--flare", study->flare,
                         "the screen's reflection of the booth light: subtract (the pipeline), "
                         "ignore (left in), or dark (no booth light on the screen)")
            ->check(CLI::IsMember({"subtract", "ignore", "dark"}))
            ->capture_default_str();
    studyCmd->add_flag("--json", study->json, "print the table and every patch as JSON");
    addSensedOptions(studyCmd, study->sensed);
    studyCmd->callback([study, &exitCode] { exitCode = studyMain(*study); });

    auto flare = std::make_shared<DisplayOptions>();
    auto* flareCmd = display->add_subcommand(
            "flare", "how much subtracting the screen's front-surface reflection changes dark "
                     "ColorChecker colours");
    addStudyOptions(flareCmd, *flare);
    flareCmd->callback([flare, &exitCode] { exitCode = flareMain(*flare); });

    auto pat = std::make_shared<PatchesOptions>();
    auto* patCmd = display->add_subcommand(
            "patches", "show a patch set (.ti1) patch by patch and collect one reading each, from "
                       "ArgyllCMS spotread or typed X Y Z, into a .ti3 (resumed when it exists)");
    patCmd->add_option("set", pat->set, "patch set, ArgyllCMS .ti1 (targen's, or --make-set's)");
    patCmd->add_option("--out", pat->out, "readings to write, .ti3 (rewritten after each)");
    patCmd->add_option("--show-dir", pat->showDir,
                       "headless display: the patch on show as DIR/patch.png and DIR/patch.txt");
    patCmd->add_option("--output", pat->output,
                       "where the patch is shown: headless (--show-dir) or kms (fullscreen on "
                       "the panel, no display server)")
            ->capture_default_str();
    patCmd->add_option("--kms-device", pat->kmsDevice, "DRM device for --output kms")
            ->capture_default_str();
    patCmd->add_option("--kms-connector", pat->kmsConnector,
                       "connector for --output kms, e.g. HDMI-A-1 (default: the first connected)");
    patCmd->add_option("--spotread", pat->spotread,
                       "meter command, e.g. 'spotread -e -x' (one key press per reading, parsed "
                       "from its 'Result is XYZ:' line); without it X Y Z are read from stdin");
    patCmd->add_option("--settle-ms", pat->settleMs, "wait after showing each patch (ms)")
            ->capture_default_str();
    patCmd->add_option("--bits", pat->bits, "panel bit depth")
            ->check(CLI::Range(1, 16))
            ->capture_default_str();
    patCmd->add_option("--make-set", pat->makeSet,
                       "write the default set (3 blacks, R, G, B ramps every --step counts with "
                       "full drive --full-repeats times, 2 whites, --colours random colours) to "
                       "this .ti1 and stop");
    patCmd->add_option("--step", pat->step, "ramp step for --make-set")
            ->check(CLI::Range(1, 64))
            ->capture_default_str();
    patCmd->add_option("--full-repeats", pat->fullDriveRepeats,
                       "readings of each primary's full drive for --make-set (their mean sets the "
                       "primary's scale)")
            ->check(CLI::Range(1, 100))
            ->capture_default_str();
    patCmd->add_option("--colours", pat->colours, "random colours for --make-set")
            ->check(CLI::Range(6, 10000))
            ->capture_default_str();
    patCmd->callback([pat, &exitCode] { exitCode = patchesMain(*pat); });

    auto syn = std::make_shared<DisplayOptions>();
    auto* synCmd = display->add_subcommand(
            "synth", "write the SYNTHETIC measurement set of the built-in ground-truth IPS panel "
                     "(the source of data/displays/wide-ips-synthetic.json)");
    synCmd->add_option("--out", syn->out, "measurement CSV to write")->required();
    synCmd->add_option("--seed", syn->seed, "meter-noise seed")->capture_default_str();
    synCmd->callback([syn, &exitCode] { exitCode = synthMain(*syn); });
}

} // namespace replica::platform
