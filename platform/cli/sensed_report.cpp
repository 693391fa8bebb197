// The end-to-end ablation table from the sensed light.
#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <pipeline/base/data_dir.h>
#include <pipeline/colour/xyz.h>
#include <pipeline/spectral/adaptive_encoding.h>
#include <platform/cli/commands.h>
#include <platform/cli/sensed_report.h>
#include <platform/logging.h>

namespace replica::platform {
namespace {

namespace pd = pipeline::display;
namespace spectral = pipeline::spectral;

struct SensedConfig {
    std::string name;
    spectral::InstrumentImpairments impairments;
    double wavelengthErrorMaxNm = 0.5;
    spectral::SensingCorrections corrections;
};

// The data-sheet instrument, each impairment off in turn, then what the appliance does about them.
std::vector<SensedConfig> sensedConfigs()
{
    const spectral::InstrumentImpairments sheet; // the defaults are the data sheet's
    std::vector<SensedConfig> c;
    spectral::InstrumentImpairments optics = spectral::idealInstrument();
    optics.fwhmNm = sheet.fwhmNm;
    c.push_back({"no impairment (1.3 nm optics only)", optics, 0.0, {}});
    c.push_back({"USB2000+ (all impairments)", sheet, 0.5, {}});
    auto off = [&](const std::string& what, auto change, double wl = 0.5) {
        SensedConfig s{"  without " + what, sheet, wl, {}};
        change(s.impairments);
        c.push_back(s);
    };
    off("1.3 nm blur (a line in 1 pixel)", [](auto& i) { i.fwhmNm = 0.0; });
    off(
            "wavelength error (+-0.5 nm)", [](auto&) {}, 0.0);
    off("stray light (0.05 %)", [](auto& i) { i.strayFraction = 0.0; });
    off("noise (shot, read, dark)", [](auto& i) { i.noise = false; });
    off("non-linearity (0.3 %)", [](auto& i) { i.residualNonlinearity = 0.0; });
    SensedConfig fixed{"corrected: stray, Hg-line shift", sheet, 0.5, {}};
    fixed.corrections.strayLight = true;
    fixed.corrections.wavelengthLines = true;
    c.push_back(fixed);
    SensedConfig avg = fixed;
    avg.name = "corrected + 5 spectra averaged";
    avg.corrections.scansAveraged = 5;
    c.push_back(avg);
    // The kiosk's own chain (state/light_estimator.cpp runs the same LiveSpectrometerChain), with
    // its defaults, on a light steady for as many spectra as it averages.
    SensedConfig live{std::string(kApplianceRow), sheet, 0.5, {}};
    live.corrections.applianceChain = true;
    live.corrections.scansAveraged = live.corrections.chain.averageSpectra;
    c.push_back(live);
    return c;
}

nlohmann::json sensedStatsJson(const pd::ErrorStats& s)
{
    return {{"n", s.count}, {"mean", s.mean}, {"std", s.std}, {"p90", s.p90}, {"max", s.max}};
}

} // namespace

void addSensedOptions(CLI::App* cmd, SensedReportOptions& o)
{
    cmd->add_flag("--sensed", o.sensed,
                  "end to end from the sensed light: each light through the simulated USB2000+ "
                  "(1.3 nm FWHM, +-0.5 nm wavelength error, 0.05 % stray light, shot/read/dark "
                  "noise at the auto-chosen integration time, 0.3 % residual non-linearity), the "
                  "renderer, the display model and the panel; each impairment off in turn");
    cmd->add_option("--mode", o.mode,
                    "with --sensed: direct (render under the sensed spectrum) or classifier (the "
                    "nearest pre-measured lamp)")
            ->check(CLI::IsMember({"direct", "classifier"}))
            ->capture_default_str();
    cmd->add_option("--draws", o.draws, "with --sensed: instruments x noise draws per light")
            ->check(CLI::Range(1, 10000))
            ->capture_default_str();
    cmd->add_option("--sensed-seed", o.seed, "with --sensed: seed of the draws")
            ->capture_default_str();
}

int sensedReport(const pd::DisplayInverse& inverse,
                 const std::function<glm::dvec3(const glm::dvec3&)>& panel,
                 const std::vector<spectral::FineLight>& lights,
                 const pd::SensedSamples& samples,
                 double lux,
                 pd::FlareHandling flare,
                 const SensedReportOptions& o)
{
    auto log = logger("replica");
    const auto data = dataDir();
    auto observer = pipeline::colour::loadCie1931(data);
    if (!observer) {
        log->error("{}", observer.error().message);
        return kExitFailure;
    }
    auto encoder = spectral::AdaptiveEncoder::createDefault(data);
    if (!encoder) {
        log->error("{}", encoder.error().message);
        return kExitFailure;
    }
    const auto basis = encoder->generalBasis();
    // The site calibrates the instrument's wavelength shift under its booth's fluorescent lamps,
    // whatever light is then sensed.
    auto booth = pd::fineBoothLights(data);
    if (!booth) {
        log->error("{}", booth.error().message);
        return kExitFailure;
    }
    nlohmann::json rows = nlohmann::json::array();
    if (!o.json) {
        fmt::print("End to end from the sensed light ({} mode, adaptive_k6, {} draws per light, "
                   "seed {}): CIEDE2000 against the real surface under the real light, absolute "
                   "(perfect diffuser at {} lux), CAT02 to D65\n\n",
                   o.mode, o.draws, o.seed, lux);
        fmt::print("{:<38} {:<15} {:^17} {:^17} {:>7} {:>6} {:>7}\n", "instrument", "light",
                   "render mean / max", "panel in-gamut", "out", "wrong", "shape");
        fmt::print("{:<38} {:<15} {:^17} {:^17} {:>7} {:>6} {:>7}\n", "", "", "", "mean / max", "n",
                   "lamp", "dist");
    }
    for (const auto& cfg : sensedConfigs()) {
        pd::SensedStudyOptions so;
        so.impairments = cfg.impairments;
        so.wavelengthErrorMaxNm = cfg.wavelengthErrorMaxNm;
        so.corrections = cfg.corrections;
        so.mode = o.mode == "classifier" ? pd::SensingMode::Classifier : pd::SensingMode::Direct;
        so.draws = o.draws;
        so.seed = o.seed;
        so.illuminanceLux = lux;
        so.flare = flare;
        so.calibrationLights = *booth;
        auto res =
                pd::sensedStudy(inverse, panel, *observer, lights, samples, &*encoder, basis, so);
        if (!res) {
            log->error("{}", res.error().message);
            return kExitFailure;
        }
        for (const auto& r : *res) {
            if (o.json) {
                rows.push_back({{"instrument", cfg.name.substr(cfg.name.find_first_not_of(' '))},
                                {"light", r.light},
                                {"appliance", cfg.name == kApplianceRow},
                                {"render", sensedStatsJson(r.render)},
                                {"panel_in_gamut", sensedStatsJson(r.panelInGamut)},
                                {"panel_out_of_gamut", sensedStatsJson(r.panelOutOfGamut)},
                                {"misclassified_draws", r.misclassified},
                                {"light_shape_distance", r.lightShapeError}});
                continue;
            }
            fmt::print("{:<38} {:<15} {:7.3f} / {:6.3f} {:7.3f} / {:6.3f} {:>7} {:>6} {:7.4f}\n",
                       cfg.name, r.light, r.render.mean, r.render.max, r.panelInGamut.mean,
                       r.panelInGamut.max, r.panelOutOfGamut.count, r.misclassified,
                       r.lightShapeError);
        }
    }
    if (o.json) {
        fmt::print("{}\n", nlohmann::json{{"mode", o.mode},
                                          {"draws", o.draws},
                                          {"seed", o.seed},
                                          {"lux", lux},
                                          {"rows", rows}}
                                   .dump(1));
    } else {
        fmt::print("\nrender: the rendered XYZ before the display; panel: what the panel emits "
                   "(hue-keeping gamut map, dithered counts); out n: samples x draws out of the "
                   "panel's gamut (not in the in-gamut figures); wrong lamp: draws the classifier "
                   "named another lamp; shape dist: sensed vs real light "
                   "(spectralShapeDistance)\n");
    }
    return kExitOk;
}

} // namespace replica::platform
