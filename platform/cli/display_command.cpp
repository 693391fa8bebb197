// 'replica display': fit a display profile from measurements, run its forward and inverse model
// for scripts and field checks, and write the synthetic measurement set the shipped profile uses.
// The subcommands' options and what they share: display_command.h.
#include <cmath>
#include <cstdio>
#include <fstream>
#include <optional>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <pipeline/base/data_dir.h>
#include <pipeline/base/output_file.h>
#include <pipeline/display/display_inverse.h>
#include <pipeline/display/display_profile.h>
#include <pipeline/offline/display/measurement_set.h>
#include <pipeline/offline/display/synthetic_display.h>
#include <platform/cli/commands.h>
#include <platform/cli/display_command.h>
#include <platform/cli/display_patches.h>
#include <platform/logging.h>

namespace replica::platform {

std::string defaultDisplayProfile()
{
    return (dataDir() / "displays" / "wide-ips-synthetic.json").string();
}

std::optional<pipeline::display::DisplayInverse> loadDisplayInverse(const std::string& path)
{
    auto model = pipeline::display::loadProfile(path);
    if (!model) {
        logger("replica")->error("{}", model.error().message);
        return std::nullopt;
    }
    auto inv = pipeline::display::DisplayInverse::build(*model);
    if (!inv) {
        logger("replica")->error("{}: {}", path, inv.error().message);
        return std::nullopt;
    }
    return std::move(*inv);
}

namespace {

namespace pd = pipeline::display;

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

int inverseMain(const DisplayOptions& o)
{
    const auto xyz = parseTriple(o.triple);
    if (!xyz) {
        logger("replica")->error("--xyz {}: expected three numbers X,Y,Z in cd/m^2", o.triple);
        return kExitUsage;
    }
    const auto inv = loadDisplayInverse(o.profile);
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
            "the ground-truth wide-luminance IPS of pipeline/offline/display/synthetic_display.cpp "
            "read "
            "through\n"
            "a simulated meter with 0.2 % + 0.005 cd/m^2 noise. Counts 8-bit; XYZ in cd/m^2.",
            o.seed);
    if (auto ok = writeOutputFile(o.out, pd::measurementCsv(rows, comment), "measurement file");
        !ok) {
        logger("replica")->error("{}", ok.error().message);
        return kExitFailure;
    }
    fmt::print("measurements: {} ({} rows)\n", o.out, rows.size());
    return kExitOk;
}

// The options the two ColorChecker studies share.
void addStudyOptions(CLI::App* cmd, DisplayOptions& opts)
{
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
}

void registerFit(CLI::App* display, int& exitCode)
{
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
    fitCmd->add_option("--white-cdm2", fit->whiteCdM2,
                       "white's luminance in cd/m^2 for a .ti3 whose XYZ are relative (white Y = "
                       "100) and that has no LUMINANCE_XYZ_CDM2 (fakeread's, dispread's without "
                       "-Y); it wins over the keyword where both are given")
            ->check(CLI::PositiveNumber);
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
                       "also write the profile as an ICC display profile (matrix/TRC, D50 PCS, "
                       "white's luminance in the lumi tag), v2.4 unless --icc-version 4");
    fitCmd->add_option("--icc-version", fit->iccVersion,
                       "ICC version of --icc: 2 (v2.4, which ArgyllCMS's iccdump, xicclu and "
                       "profcheck read) or 4 (v4.3)")
            ->check(CLI::IsMember({2, 4}))
            ->capture_default_str();
    fitCmd->add_flag("--json", fit->json, "print the fit report as JSON");
    fitCmd->callback([fit, &exitCode] { exitCode = displayFitMain(*fit); });
}

// 'inverse' and 'forward': the profile's model for scripts and field checks.
void registerModel(CLI::App* display, int& exitCode)
{
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
}

void registerStudies(CLI::App* display, int& exitCode)
{
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
    studyCmd->callback([study, &exitCode] { exitCode = displayStudyMain(*study); });

    auto flare = std::make_shared<DisplayOptions>();
    auto* flareCmd = display->add_subcommand(
            "flare", "how much subtracting the screen's front-surface reflection changes dark "
                     "ColorChecker colours");
    addStudyOptions(flareCmd, *flare);
    flareCmd->callback([flare, &exitCode] { exitCode = displayFlareMain(*flare); });
}

void registerPatches(CLI::App* display, int& exitCode)
{
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
}

void registerSynth(CLI::App* display, int& exitCode)
{
    auto syn = std::make_shared<DisplayOptions>();
    auto* synCmd = display->add_subcommand(
            "synth", "write the SYNTHETIC measurement set of the built-in ground-truth IPS panel "
                     "(the source of data/displays/wide-ips-synthetic.json)");
    synCmd->add_option("--out", syn->out, "measurement CSV to write")->required();
    synCmd->add_option("--seed", syn->seed, "meter-noise seed")->capture_default_str();
    synCmd->callback([syn, &exitCode] { exitCode = synthMain(*syn); });
}

} // namespace

void registerDisplayCommand(CLI::App& app, int& exitCode)
{
    auto* display = app.add_subcommand(
            "display",
            "display characterisation: fit a profile, run its forward and inverse model");
    display->require_subcommand(1);

    registerFit(display, exitCode);
    registerModel(display, exitCode);
    registerStudies(display, exitCode);
    registerPatches(display, exitCode);
    registerSynth(display, exitCode);
}

} // namespace replica::platform
