// 'replica display fit': a display profile fitted to measurements
// (pipeline/offline/display/display_fit.h), written as JSON (and ICC v2.4 or v4 on request), and
// its fit report printed.
#include <filesystem>
#include <fstream>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <nlohmann/json.hpp>

#include <pipeline/display/display_profile.h>
#include <pipeline/display/icc_profile.h>
#include <pipeline/offline/display/cgats.h>
#include <pipeline/offline/display/display_fit.h>
#include <pipeline/offline/display/synthetic_display.h>
#include <pipeline/offline/display/viewing_angle_csv.h>
#include <platform/cli/commands.h>
#include <platform/cli/display_command.h>
#include <platform/logging.h>

namespace replica::platform {
namespace {

namespace pd = pipeline::display;

// The outputs are checked before the fit, not after it: an unwritable --out or --icc fails at
// once, and a file that did not exist is not left behind.
bool outputsWritable(const DisplayOptions& o)
{
    auto log = logger("replica");
    for (const std::string& path : {o.out, o.icc}) {
        if (path.empty()) {
            continue;
        }
        std::error_code ec;
        const bool existed = std::filesystem::exists(path, ec);
        if (existed && !std::filesystem::is_regular_file(path, ec)) {
            log->error("{}: not a regular file; give a file path to write", path);
            return false;
        }
        const bool writable =
                static_cast<bool>(std::ofstream(path, std::ios::binary | std::ios::app));
        if (!existed) {
            std::filesystem::remove(path, ec);
        }
        if (!writable) {
            log->error("{}: cannot write here (check the folder exists and is writable)", path);
            return false;
        }
    }
    return true;
}

pd::FitOptions fitOptions(const DisplayOptions& o, const pd::MeasurementSet& set)
{
    pd::FitOptions fo;
    fo.name = o.name.empty() ? std::filesystem::path(o.out).stem().string() : o.name;
    fo.synthetic = o.synthetic;
    fo.toneMethod = o.tone == "interpolate" ? pd::ToneMethod::Interpolate : pd::ToneMethod::Robust;
    fo.condition = o.measuredIn == "dark" ? pd::MeasurementCondition::Dark
                                          : pd::MeasurementCondition::LitBooth;
    fo.description = fmt::format("fitted by 'replica display fit' from {} ({} rows, {}-bit){}",
                                 std::filesystem::path(o.measurements).filename().string(),
                                 set.rows.size(), set.bitDepth,
                                 o.synthetic ? "; SYNTHETIC measurements, not a real panel" : "");
    return fo;
}

// The viewing-angle table: measured (--viewing-table), or the synthetic panel's.
bool attachViewingTable(const DisplayOptions& o, pd::DisplayModel& model)
{
    auto log = logger("replica");
    if (!o.viewingTable.empty()) {
        auto table = pd::loadViewingAngleCsv(o.viewingTable);
        if (!table) {
            log->error("{}", table.error().message);
            return false;
        }
        model.viewing = std::move(*table);
    } else if (o.synthetic) {
        // The synthetic panel's viewing-angle table travels with its profile.
        model.viewing = pd::wideIpsViewingAngles();
    }
    return true;
}

bool writeIcc(const pd::DisplayModel& model, const std::string& path, int version)
{
    auto log = logger("replica");
    auto icc = pd::writeIccProfile(model, path,
                                   version == 4 ? pd::IccVersion::V4_3 : pd::IccVersion::V2_4);
    if (!icc) {
        log->error("{}", icc.error().message);
        return false;
    }
    if (icc->blackClipped) {
        log->warn("{}: black lies outside the primaries' triangle; the ICC profile's black is "
                  "the nearest the matrix/TRC form holds",
                  path);
    }
    if (icc->crosstalkOmitted) {
        log->warn("{}: the fit's crosstalk term (white {:.2f} % from R+G+B) is left out: a "
                  "matrix/TRC profile holds only the additive part; the JSON profile has it",
                  path,
                  100.0 * (model.forward(glm::dvec3(model.maxCount())).y - model.whiteXyz().y) /
                          model.whiteXyz().y);
    }
    return true;
}

void printFitJson(const pd::DisplayModel& model, const std::string& out)
{
    const auto& f = model.fit;
    fmt::print("{}\n",
               nlohmann::json{
                       {"profile", out},
                       {"held_out_colours", f.heldOutColours},
                       {"held_out_mean_de00", f.heldOutMeanDe00},
                       {"held_out_p90_de00", f.heldOutP90De00},
                       {"held_out_max_de00", f.heldOutMaxDe00},
                       {"additivity_de00", f.additivityDe00},
                       {"additivity_luminance_percent", f.additivityLuminancePercent},
                       {"additivity_noise_de00", f.additivityNoiseDe00},
                       {"additivity_luminance_sigma_percent", f.additivityLuminanceSigmaPercent},
                       {"additive_within_noise", f.additiveWithinNoise},
                       {"noise_percent", f.noisePercent},
                       {"held_out_noise_mean_de00", f.heldOutNoiseMeanDe00},
                       {"tone_shape", f.toneShape},
                       {"inverse_counts_rms", f.inverseCountsRms},
                       {"inverse_counts_max", f.inverseCountsMax},
                       {"gamut_edge_tolerance", model.gamutEdgeTolerance},
                       {"crosstalk_model", f.crosstalkModel},
                       {"crosstalk_gain_de00", f.crosstalkGainDe00},
                       {"ramp_levels", f.rampLevels},
                       {"gog_only_for_short_ramps", f.gogOnlyForShortRamps}}
                       .dump());
}

// The robust fit's figures: the meter's noise, the tone curves and the inverse's error, the gamut
// edge, the crosstalk term. 'w': the model's white.
void printRobustFit(const pd::DisplayModel& model, const glm::dvec3& w)
{
    const auto& f = model.fit;
    fmt::print("meter noise (from the ramps' residuals): {:.3f}% per XYZ component; held-out "
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
               model.gamutEdgeTolerance);
    if (model.hasCrosstalk()) {
        const glm::dmat3& c = model.crosstalk;
        fmt::print("crosstalk ({}; one-parameter coefficient {:.1f} standard errors from "
                   "zero, cross-validated gain dE00 {:.4f}): r + C (rg, gb, br), "
                   "C rows R {:+.5f} {:+.5f} {:+.5f} G {:+.5f} {:+.5f} {:+.5f} B {:+.5f} "
                   "{:+.5f} {:+.5f}; white {:+.2f}% from black + R + G + B\n",
                   f.crosstalkModel, f.crosstalkZ, f.crosstalkGainDe00, c[0][0], c[1][0], c[2][0],
                   c[0][1], c[1][1], c[2][1], c[0][2], c[1][2], c[2][2],
                   100.0 * (w.y - model.whiteXyz().y) / model.whiteXyz().y);
    } else if (!f.crosstalkModel.empty()) {
        fmt::print("crosstalk: none (one-parameter coefficient {:.1f} standard errors from "
                   "zero, needs 3; cross-validated gain dE00 {:.4f}, needs 0.001)\n",
                   f.crosstalkZ, f.crosstalkGainDe00);
    }
}

void printFitText(const pd::DisplayModel& model, const DisplayOptions& o)
{
    const auto& f = model.fit;
    // The model's white (with a crosstalk term, below black + R + G + B).
    const glm::dvec3 w = model.forward(glm::dvec3(model.maxCount()));
    fmt::print("profile: {}{}\n", o.out,
               o.icc.empty() ? std::string()
                             : fmt::format(" (and ICC {}: {})", o.iccVersion == 4 ? "v4.3" : "v2.4",
                                           o.icc));
    fmt::print("white {:.1f} cd/m^2, black {:.3f} cd/m^2, {}-bit\n", w.y, model.blackXyz.y,
               model.bitDepth);
    fmt::print("held-out dE00 over {} colours: mean {:.3f}, 90th {:.3f}, max {:.3f} "
               "(direct primaries: mean {:.3f}; training mean {:.3f})\n",
               f.heldOutColours, f.heldOutMeanDe00, f.heldOutP90De00, f.heldOutMaxDe00,
               f.directPrimariesHeldOutMeanDe00, f.trainingMeanDe00);
    if (f.noisePercent >= 0.0) {
        printRobustFit(model, w);
    }
    if (f.additivityDe00 >= 0.0 && f.additivityNoiseDe00 >= 0.0) {
        fmt::print("additivity: white vs black + R + G + B dE00 {:.3f} (the noise alone gives "
                   "up to {:.3f}, 99.9th percentile), luminance {:+.2f}% +- {:.2f}% (1 sigma): "
                   "{}\n",
                   f.additivityDe00, f.additivityNoiseDe00, f.additivityLuminancePercent,
                   f.additivityLuminanceSigmaPercent,
                   f.additiveWithinNoise ? "additive within the noise"
                                         : "NOT additive: channel interaction beyond the noise");
    } else if (f.additivityDe00 >= 0.0) {
        fmt::print("additivity: white vs R+G+B dE00 {:.3f}, luminance {:+.2f}%\n", f.additivityDe00,
                   f.additivityLuminancePercent);
    }
    if (f.gogOnlyForShortRamps) {
        fmt::print("short ramps: R {} G {} B {} non-zero levels; a channel with fewer than 8 has "
                   "the GOG curve alone (not cross-validated against GOGO or a spline, its noise "
                   "estimate from 3 parameters' residuals); for those, add single-channel steps "
                   "(ArgyllCMS: targen -d3 -s 9)\n",
                   f.rampLevels[0], f.rampLevels[1], f.rampLevels[2]);
    }
    fmt::print("primary chromaticity drift along ramps (max |dxy|): R {:.4f} G {:.4f} B "
               "{:.4f}; ramp points pooled for monotonicity: {}\n",
               f.chromaticityDrift[0], f.chromaticityDrift[1], f.chromaticityDrift[2],
               f.monotonicCorrections);
}

} // namespace

int displayFitMain(const DisplayOptions& o)
{
    auto log = logger("replica");
    if (o.measuredIn != "dark" && o.measuredIn != "lit-booth") {
        log->error("--measured-in {}: expected 'dark' or 'lit-booth'", o.measuredIn);
        return kExitUsage;
    }
    auto set = pd::loadMeasurements(o.measurements, o.bits, o.whiteCdM2);
    if (!set) {
        log->error("{}", set.error().message);
        return kExitFailure;
    }
    if (!outputsWritable(o)) {
        return kExitFailure;
    }
    auto model = pd::fitDisplay(*set, fitOptions(o, *set));
    if (!model) {
        log->error("{}", model.error().message);
        return kExitFailure;
    }
    if (!attachViewingTable(o, *model)) {
        return kExitFailure;
    }
    if (auto ok = pd::saveProfile(*model, o.out); !ok) {
        log->error("{}", ok.error().message);
        return kExitFailure;
    }
    if (!o.icc.empty() && !writeIcc(*model, o.icc, o.iccVersion)) {
        return kExitFailure;
    }
    if (o.json) {
        printFitJson(*model, o.out);
    } else {
        printFitText(*model, o);
    }
    return kExitOk;
}

} // namespace replica::platform
