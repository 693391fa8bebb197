// 'replica display': fit a display profile from measurements, run its forward and inverse model
// for scripts and field checks, and write the synthetic measurement set the shipped profile uses.
#include <cmath>
#include <cstdio>
#include <fstream>
#include <optional>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <pipeline/display/display_fit.h>
#include <pipeline/display/display_inverse.h>
#include <pipeline/display/display_profile.h>
#include <pipeline/display/synthetic_display.h>
#include <platform/cli/commands.h>
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
    int bits = 0;
    bool synthetic = false;
    bool json = false;
    bool clip = false;
    std::uint64_t seed = 1;
};

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
    auto set = pd::loadMeasurementCsv(o.measurements, o.bits);
    if (!set) {
        log->error("{}", set.error().message);
        return kExitFailure;
    }
    pd::FitOptions fo;
    fo.name = o.name.empty() ? std::filesystem::path(o.out).stem().string() : o.name;
    fo.synthetic = o.synthetic;
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
    if (o.synthetic) {
        // The synthetic panel's viewing-angle table travels with its profile.
        model->viewing = pd::wideIpsViewingAngles();
    }
    if (auto ok = pd::saveProfile(*model, o.out); !ok) {
        log->error("{}", ok.error().message);
        return kExitFailure;
    }
    const auto& f = model->fit;
    if (o.json) {
        fmt::print("{}\n", nlohmann::json{{"profile", o.out},
                                          {"held_out_colours", f.heldOutColours},
                                          {"held_out_mean_de00", f.heldOutMeanDe00},
                                          {"held_out_p90_de00", f.heldOutP90De00},
                                          {"held_out_max_de00", f.heldOutMaxDe00},
                                          {"additivity_de00", f.additivityDe00}}
                                   .dump());
    } else {
        const glm::dvec3 w = model->whiteXyz();
        fmt::print("profile: {}\n", o.out);
        fmt::print("white {:.1f} cd/m^2, black {:.3f} cd/m^2, {}-bit\n", w.y, model->blackXyz.y,
                   model->bitDepth);
        fmt::print("held-out dE00 over {} colours: mean {:.3f}, 90th {:.3f}, max {:.3f} "
                   "(direct primaries: mean {:.3f}; training mean {:.3f})\n",
                   f.heldOutColours, f.heldOutMeanDe00, f.heldOutP90De00, f.heldOutMaxDe00,
                   f.directPrimariesHeldOutMeanDe00, f.trainingMeanDe00);
        if (f.additivityDe00 >= 0.0) {
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
            "fit", "fit a display profile to measurements MEAS.csv (columns R,G,B,X,Y,Z: counts "
                   "at the panel's bit depth, XYZ in cd/m^2)");
    fitCmd->add_option("measurements", fit->measurements, "measurement CSV")->required();
    fitCmd->add_option("--out", fit->out, "profile to write (JSON)")->required();
    fitCmd->add_option("--name", fit->name, "profile name (default: the output file's stem)");
    fitCmd->add_option("--bits", fit->bits, "panel bit depth (default: from the largest count)")
            ->check(CLI::Range(1, 16));
    fitCmd->add_option("--measured-in", fit->measuredIn,
                       "dark, or lit-booth (the black then already holds the screen's reflection "
                       "of the booth light, which is then not subtracted again)")
            ->capture_default_str();
    fitCmd->add_flag("--synthetic", fit->synthetic,
                     "mark the profile as built from synthetic measurements (and attach the "
                     "synthetic panel's viewing-angle table)");
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

    auto syn = std::make_shared<DisplayOptions>();
    auto* synCmd = display->add_subcommand(
            "synth", "write the SYNTHETIC measurement set of the built-in ground-truth IPS panel "
                     "(the source of data/displays/wide-ips-synthetic.json)");
    synCmd->add_option("--out", syn->out, "measurement CSV to write")->required();
    synCmd->add_option("--seed", syn->seed, "meter-noise seed")->capture_default_str();
    synCmd->callback([syn, &exitCode] { exitCode = synthMain(*syn); });
}

} // namespace replica::platform
