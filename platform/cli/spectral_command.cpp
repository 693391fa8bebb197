// 'replica spectral': eval (representation accuracy on a light and a reflectance set), metamers,
// and the registration of fit (spectral_fit.cpp: derive the channel data the appliance ships).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <string>
#include <tuple>
#include <vector>

#include <CLI/CLI.hpp>
#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <pipeline/base/data_dir.h>
#include <pipeline/base/output_file.h>
#include <pipeline/colour/spectral_table.h>
#include <pipeline/display/display_inverse.h>
#include <pipeline/display/display_profile.h>
#include <pipeline/offline/spectral/accuracy.h>
#include <pipeline/offline/spectral/basis_fit.h>
#include <pipeline/offline/spectral/metamers.h>
#include <pipeline/spectral/representation_catalogue.h>
#include <pipeline/spectral/six_channel_model.h>
#include <platform/cli/commands.h>
#include <platform/cli/sensed_report.h>
#include <platform/cli/spectral_fit.h>

namespace replica::platform {
namespace {

namespace colour = pipeline::colour;
namespace spectral = pipeline::spectral;

struct EvalOptions {
    std::string illuminant;
    std::string reflectances;
    std::string representation = spectral::kApplianceRepresentation;
    std::string encodedFor; // adaptive representations: the light the surfaces were encoded for
    bool json = false;
    SensedReportOptions sensed;
    std::string profile; // --sensed: the display profile (default: the shipped synthetic one)
};

const char* adaptationName(colour::Adaptation a)
{
    switch (a) {
    case colour::Adaptation::Cat02:
        return "CAT02 to D65";
    case colour::Adaptation::XyzScaling:
        return "XYZ scaling to D65";
    case colour::Adaptation::None:
        break;
    }
    return "none (the light has no Z)";
}

nlohmann::json labJson(const colour::Lab& lab)
{
    return nlohmann::json::array({lab.L, lab.a, lab.b});
}

// --sensed: the light through the simulated spectrometer, adaptive_k6 (the appliance's), the
// display.
int runSensedEval(const EvalOptions& o,
                  const colour::SpectralTable& lightTable,
                  const spectral::NamedSpectra& set)
{
    auto fail = [](const std::string& msg) {
        std::fprintf(stderr, "replica spectral eval: %s\n", msg.c_str());
        return kExitFailure;
    };
    const auto data = dataDir();
    if (o.representation != spectral::kApplianceRepresentation || !o.encodedFor.empty()) {
        return fail(fmt::format("--sensed renders as the appliance does ({}, encoded for the "
                                "sensed light); drop --representation and --encoded-for",
                                spectral::kApplianceRepresentation));
    }
    auto fine = spectral::restoreLines(lightTable, "value");
    if (!fine) {
        return fail(fine.error().message);
    }
    fine->name = std::filesystem::path(o.illuminant).stem().string();
    const std::string profile = o.profile.empty()
                                        ? (data / "displays" / "wide-ips-synthetic.json").string()
                                        : o.profile;
    auto model = pipeline::display::loadProfile(profile);
    if (!model) {
        return fail(model.error().message);
    }
    auto inverse = pipeline::display::DisplayInverse::build(*model);
    if (!inverse) {
        return fail(fmt::format("{}: {}", profile, inverse.error().message));
    }
    const pipeline::display::DisplayModel panelModel = *model;
    SensedReportOptions so = o.sensed;
    so.json = o.json;
    return sensedReport(
            *inverse, [panelModel](const glm::dvec3& c) { return panelModel.forward(c); }, {*fine},
            pipeline::display::SensedSamples{set.names, set.spectra}, 2000.0,
            pipeline::display::FlareHandling::InBoothSubtract, so);
}

// The representation's report, as a table or JSON.
int printEvalReport(const EvalOptions& o,
                    const spectral::AccuracyReport& report,
                    const spectral::NamedSpectra& set)
{
    if (o.json) {
        nlohmann::json out;
        out["representation"] = report.representation;
        out["illuminant"] = o.illuminant;
        if (!o.encodedFor.empty()) {
            out["encoded_for"] = o.encodedFor;
        }
        out["reflectances"] = o.reflectances;
        out["white"] = set.names[report.whiteIndex];
        out["grid"] = "380-730 nm, 10 nm (36 bands)";
        out["adaptation"] = adaptationName(report.adaptation);
        out["samples"] = nlohmann::json::array();
        for (const auto& s : report.samples) {
            out["samples"].push_back({{"name", s.name},
                                      {"lab_reference", labJson(s.labReference)},
                                      {"lab_approx", labJson(s.labApprox)},
                                      {"de00", s.de00}});
        }
        out["stats"] = {{"mean", report.stats.mean},
                        {"std", report.stats.std},
                        {"p90", report.stats.p90},
                        {"max", report.stats.max}};
        std::cout << out.dump(2) << "\n";
        return kExitOk;
    }
    std::cout << fmt::format("representation {}, white sample '{}', CIEDE2000 against spectral36 "
                             "({}, white Y = 1/1.13)\n",
                             report.representation, set.names[report.whiteIndex],
                             adaptationName(report.adaptation));
    if (report.adaptation == colour::Adaptation::XyzScaling) {
        std::cout
                << "(CAT02 cannot adapt this light: its white has a sharpened response <= 0, as a "
                   "narrow-band light's does; its white is scaled onto D65's in XYZ instead)\n";
    } else if (report.adaptation == colour::Adaptation::None) {
        std::cout << "(this light cannot be adapted to D65: its white has no Z (the observer's "
                     "z-bar is 0 over all of its power, as at 650-730 nm), and no scaling makes "
                     "0 into D65's Z; Lab is against D65's white unadapted, so its a* and b* "
                     "show the light's own colour)\n";
    }
    std::cout << fmt::format("{:<24} {:>26} {:>26} {:>8}\n", "sample", "Lab reference",
                             "Lab approx", "de00");
    for (const auto& s : report.samples) {
        std::cout << fmt::format("{:<24} {:8.3f} {:8.3f} {:8.3f} {:8.3f} {:8.3f} {:8.3f} {:8.4f}\n",
                                 s.name, s.labReference.L, s.labReference.a, s.labReference.b,
                                 s.labApprox.L, s.labApprox.a, s.labApprox.b, s.de00);
    }
    std::cout << fmt::format("mean {:.4f}  std {:.4f}  p90 {:.4f}  max {:.4f}\n", report.stats.mean,
                             report.stats.std, report.stats.p90, report.stats.max);
    return kExitOk;
}

int runEval(const EvalOptions& o)
{
    auto fail = [](const std::string& msg) {
        std::fprintf(stderr, "replica spectral eval: %s\n", msg.c_str());
        return kExitFailure;
    };
    const auto data = dataDir();
    auto obs = colour::loadCie1931(data);
    if (!obs) {
        return fail(obs.error().message);
    }
    auto d65 = spectral::loadCieIlluminant(data, "D65");
    if (!d65) {
        return fail(d65.error().message);
    }
    auto lightTable = colour::loadSpectralCsv(o.illuminant);
    if (!lightTable) {
        return fail(lightTable.error().message);
    }
    auto light = lightTable->spectrum("value", colour::GridSampling::BandAverage);
    if (!light) {
        return fail(light.error().message);
    }
    if (auto ok = spectral::checkLightScale(*obs, *light, o.illuminant); !ok) {
        return fail(ok.error().message);
    }
    auto set = spectral::loadReflectances(o.reflectances);
    if (!set) {
        return fail(set.error().message);
    }
    if (o.sensed.sensed) {
        return runSensedEval(o, *lightTable, *set);
    }
    auto rep = spectral::makeRepresentation(data, *obs, *d65, o.representation);
    if (!rep) {
        return fail(rep.error().message);
    }
    // An adaptive representation is encoded for the light it renders under unless --encoded-for
    // names another (the frames between a light change and the end of the re-encode).
    std::unique_ptr<spectral::Representation> encoded;
    if (!o.encodedFor.empty()) {
        auto forTable = colour::loadSpectralCsv(o.encodedFor);
        if (!forTable) {
            return fail(forTable.error().message);
        }
        auto forLight = forTable->spectrum("value", colour::GridSampling::BandAverage);
        if (!forLight) {
            return fail(forLight.error().message);
        }
        // A dark light is the encoder's to refuse (it says what the appliance then does).
        if (auto ok = spectral::checkLightScale(*obs, *forLight, o.encodedFor);
            !ok && forLight->max() > 0.0) {
            return fail(ok.error().message);
        }
        auto adapted = (*rep)->adaptedTo(*forLight);
        if (!adapted) {
            return fail(fmt::format("{}: {}", o.encodedFor, adapted.error().message));
        }
        if (!*adapted) {
            return fail(fmt::format("--encoded-for applies to a light-adaptive representation "
                                    "(adaptive_k6); '{}' encodes the same for every light",
                                    o.representation));
        }
        encoded = std::move(*adapted);
    }
    auto report =
            spectral::evaluateRepresentation(*obs, *d65, encoded ? *encoded : **rep, *light, *set);
    if (!report) {
        return fail(fmt::format("{}: {}", o.reflectances, report.error().message));
    }
    return printEvalReport(o, *report, *set);
}

struct MetamerOptions {
    std::string matchLight = "A";
    std::string mismatchLight = "D65";
    std::string seeds = "ces99";
    std::string out;
    std::size_t count = 6;
    double minMismatch = 3.0;
    double targetMismatch = 8.0;
};

int runMetamers(const MetamerOptions& o)
{
    auto fail = [](const std::string& msg) {
        std::fprintf(stderr, "replica spectral metamers: %s\n", msg.c_str());
        return kExitFailure;
    };
    const auto data = dataDir();
    auto obs = colour::loadCie1931(data);
    auto basis = colour::loadDefaultChannelBasis(data);
    auto match = spectral::loadCieIlluminant(data, o.matchLight);
    auto mismatch = spectral::loadCieIlluminant(data, o.mismatchLight);
    auto seeds = spectral::loadReflectanceSet(data, o.seeds);
    for (const Error* e : {obs ? nullptr : &obs.error(), basis ? nullptr : &basis.error(),
                           match ? nullptr : &match.error(), mismatch ? nullptr : &mismatch.error(),
                           seeds ? nullptr : &seeds.error()}) {
        if (e != nullptr) {
            return fail(e->message);
        }
    }
    const auto pairs = spectral::findMetamerPairs(*obs, *basis, *match, *mismatch, *seeds, o.count,
                                                  o.minMismatch, o.targetMismatch);
    if (pairs.empty()) {
        return fail(fmt::format("no seed in '{}' gives a pair with CIEDE2000 >= {} under {}",
                                o.seeds, o.minMismatch, o.mismatchLight));
    }
    const std::filesystem::path out =
            o.out.empty() ? data / "scenes" / "metamers" /
                                    fmt::format("metamers_{}_{}.csv", o.matchLight, o.mismatchLight)
                          : std::filesystem::path(o.out);
    auto saved = spectral::saveMetamerPairs(pairs, out,
                                            fmt::format("written by 'replica spectral metamers' in "
                                                        "the span of {} from {} seeds; same XYZ "
                                                        "under {}, different under {}",
                                                        basis->name, o.seeds, o.matchLight,
                                                        o.mismatchLight));
    if (!saved) {
        return fail(saved.error().message);
    }
    for (const auto& p : pairs) {
        std::cout << fmt::format("{} (from {}): de00 {:.4f} under {}, {:.2f} under {}\n", p.name,
                                 p.seed, p.de00Match, o.matchLight, p.de00Mismatch,
                                 o.mismatchLight);
    }
    std::cout << "wrote " << out.string() << "\n";
    return kExitOk;
}

} // namespace

void registerSpectralCommand(CLI::App& app, int& exitCode)
{
    auto* spectralCmd =
            app.add_subcommand("spectral", "spectral representations: accuracy and fitting");
    spectralCmd->require_subcommand(1);

    auto eval = std::make_shared<EvalOptions>();
    auto* e = spectralCmd->add_subcommand("eval",
                                          "CIEDE2000 of a representation against the full-spectral "
                                          "calculation, for one light and a "
                                          "reflectance set (white patch Y = 1/1.13, CAT02 to D65)");
    e->add_option("--illuminant", eval->illuminant,
                  "LIGHT.csv with columns wavelength_nm,value (any grid "
                  "covering 380-730 nm)")
            ->required();
    e->add_option(
             "--reflectances", eval->reflectances,
             "SET.csv: wavelength_nm then one column per sample; the white is the sample named "
             "'white', else the one with the highest Y")
            ->required();
    e->add_option("--representation", eval->representation,
                  fmt::format("one of {}", fmt::join(spectral::representationNames(), ", ")))
            ->capture_default_str();
    e->add_option("--encoded-for", eval->encodedFor,
                  "adaptive_k6 only: evaluate surfaces encoded for this light (CSV as "
                  "--illuminant) while rendering under --illuminant");
    e->add_flag("--json", eval->json, "print JSON with 'samples' and 'stats'");
    addSensedOptions(e, eval->sensed);
    e->add_option(
            "--profile", eval->profile,
            "with --sensed: display profile (default: data/displays/wide-ips-synthetic.json)");
    e->callback([eval, &exitCode] { exitCode = runEval(*eval); });

    auto fit = std::make_shared<SpectralFitOptions>();
    auto* f = spectralCmd->add_subcommand(
            "fit", "derive the channel data the appliance ships "
                   "(replica_k6.csv, general_k6.csv, pca6.csv, paper6.csv) from "
                   "named training sets");
    f->add_option("--reflectances", fit->reflectances,
                  "training reflectances: comma-separated set names (ces99, tcs14) or CSV paths")
            ->capture_default_str();
    f->add_option("--lights", fit->lights,
                  fmt::format("training lights: comma-separated CIE illuminant names (default: {})",
                              fmt::join(spectral::evaluationLightNames(), ",")));
    f->add_option("--weights", fit->weights,
                  "weights of named training lights in replica_k6, NAME=W,... (others weigh 1)")
            ->capture_default_str();
    f->add_option("--out", fit->out, "output folder (default: the data folder's channels/)");
    f->add_option("--rounds", fit->rounds, "alternating least-squares rounds for paper6")
            ->capture_default_str()
            ->check(CLI::Range(1, 100000));
    f->callback([fit, &exitCode] { exitCode = runSpectralFit(*fit); });

    auto met = std::make_shared<MetamerOptions>();
    auto* m = spectralCmd->add_subcommand(
            "metamers",
            "write metameric reflectance pairs (same XYZ under one light, different under another) "
            "inside the default channel basis, as a scene target");
    m->add_option("--match-light", met->matchLight, "CIE illuminant of the match")
            ->capture_default_str();
    m->add_option("--mismatch-light", met->mismatchLight, "CIE illuminant of the mismatch")
            ->capture_default_str();
    m->add_option("--seeds", met->seeds, "reflectance set the pairs grow from")
            ->capture_default_str();
    m->add_option("--count", met->count, "number of pairs")
            ->capture_default_str()
            ->check(CLI::Range(1, 50));
    m->add_option("--min-mismatch", met->minMismatch, "smallest CIEDE2000 under the mismatch light")
            ->capture_default_str();
    m->add_option("--target-mismatch", met->targetMismatch,
                  "CIEDE2000 the pairs are eased back to under the mismatch light (0: as large as "
                  "possible)")
            ->capture_default_str();
    m->add_option("--out", met->out,
                  "output CSV (default: data/scenes/metamers/metamers_<match>_<mismatch>.csv)");
    m->callback([met, &exitCode] { exitCode = runMetamers(*met); });
}

} // namespace replica::platform
