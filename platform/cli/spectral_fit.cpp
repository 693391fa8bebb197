// 'replica spectral fit': the training sets and lights read, the fits run, their files written.
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

std::vector<std::string> splitList(const std::string& s)
{
    std::vector<std::string> out;
    std::stringstream in(s);
    std::string item;
    while (std::getline(in, item, ',')) {
        if (!item.empty()) {
            out.push_back(item);
        }
    }
    return out;
}

// '--weights NAME=W,...' as (name, weight) pairs; W a finite number >= 0.
Expected<std::vector<std::pair<std::string, double>>> parseWeights(const std::string& text)
{
    std::vector<std::pair<std::string, double>> weights;
    for (const auto& item : splitList(text)) {
        const auto eq = item.find('=');
        if (eq == std::string::npos || eq == 0) {
            return makeError(ErrorCode::InvalidArgument,
                             fmt::format("--weights: '{}' is not NAME=WEIGHT", item));
        }
        double w = 0.0;
        try {
            std::size_t used = 0;
            w = std::stod(item.substr(eq + 1), &used);
            if (used != item.size() - eq - 1 || !(w >= 0.0) || !std::isfinite(w)) {
                throw std::invalid_argument("weight");
            }
        } catch (const std::exception&) {
            return makeError(ErrorCode::InvalidArgument,
                             fmt::format("--weights: '{}' has no finite non-negative number after "
                                         "'='",
                                         item));
        }
        weights.emplace_back(item.substr(0, eq), w);
    }
    return weights;
}

// The training reflectances: named sets or CSV files, never the ColorChecker (the evaluation set).
Expected<spectral::NamedSpectra> loadTraining(const std::filesystem::path& data,
                                              const std::string& names)
{
    spectral::NamedSpectra training;
    for (const auto& name : splitList(names)) {
        if (name.rfind("colorchecker", 0) == 0) {
            return makeError(ErrorCode::InvalidArgument,
                             fmt::format("'{}' is the evaluation set; train on sets that exclude "
                                         "it (ces99, or a CSV of your own)",
                                         name));
        }
        auto set = name.find(".csv") != std::string::npos
                           ? spectral::loadReflectances(name)
                           : spectral::loadReflectanceSet(data, name);
        if (!set) {
            return tl::unexpected(set.error());
        }
        training.append(*set);
    }
    return training;
}

// The training lights (--lights, else the evaluation lights) and any light --weights names
// besides, with each one's weight in replica_k6 (others 1).
Expected<spectral::NamedSpectra>
loadFitLights(const std::filesystem::path& data,
              const std::vector<std::string>& lightNames,
              const std::vector<std::pair<std::string, double>>& weights,
              std::vector<double>& lightWeights)
{
    spectral::NamedSpectra lights;
    for (const auto& name : lightNames) {
        auto l = spectral::loadCieIlluminant(data, name);
        if (!l) {
            return tl::unexpected(l.error());
        }
        lights.names.push_back(name);
        lights.spectra.push_back(*l);
    }
    for (const auto& [name, w] : weights) {
        if (std::find(lights.names.begin(), lights.names.end(), name) == lights.names.end()) {
            auto l = spectral::loadCieIlluminant(data, name);
            if (!l) {
                return makeError(l.error().code, fmt::format("--weights: {}", l.error().message));
            }
            lights.names.push_back(name);
            lights.spectra.push_back(*l);
        }
    }
    for (const auto& name : lights.names) {
        double w = 1.0;
        for (const auto& [n, v] : weights) {
            if (n == name) {
                w = v;
            }
        }
        lightWeights.push_back(w);
    }
    return lights;
}

// The output folder, checked before the fits (minutes), not after them.
Expected<void> checkOutDir(const std::filesystem::path& outDir)
{
    std::error_code ec;
    std::filesystem::create_directories(outDir, ec);
    if (ec || !std::filesystem::is_directory(outDir)) {
        return makeError(ErrorCode::InvalidArgument,
                         fmt::format("--out {}: cannot use it as the output folder ({}); give a "
                                     "writable folder",
                                     outDir.string(), ec ? ec.message() : "not a folder"));
    }
    const std::filesystem::path probe = outDir / ".replica-spectral-fit-write-test";
    const bool writable = static_cast<bool>(writeOutputFile(probe, "", "write test"));
    std::filesystem::remove(probe, ec);
    if (!writable) {
        return makeError(ErrorCode::InvalidArgument,
                         fmt::format("--out {}: the folder is not writable; give a writable "
                                     "folder",
                                     outDir.string()));
    }
    return {};
}

// paper6's alternating fit is not convex, so its start matters. It starts from the light-aware
// basis with the three booth lamps weighted 10 : 1, which generalised best to the ColorChecker of
// the starts tried (that one, general_k6, replica_k6 as weighted now; docs/accuracy.md).
Expected<spectral::SixChannelModel> fitPaperSix(const colour::Observer& obs,
                                                const colour::Spectrum& d65,
                                                const spectral::NamedSpectra& training,
                                                const spectral::NamedSpectra& lights,
                                                int rounds,
                                                spectral::SixChannelFitReport& report)
{
    spectral::BasisFitOptions paperStart;
    for (const auto& name : lights.names) {
        const bool booth = name == "A" || name == "F8" || name == "F7";
        paperStart.lightWeights.push_back(booth ? 10.0 : 1.0);
    }
    auto start = spectral::fitChannelBasis(obs, d65, training, lights, paperStart, "start");
    if (!start) {
        return tl::unexpected(start.error());
    }
    return spectral::fitSixChannelModel(obs, d65, training, lights, *start, rounds, "paper6",
                                        &report);
}

} // namespace

int runSpectralFit(const SpectralFitOptions& o)
{
    auto fail = [](const std::string& msg) {
        std::fprintf(stderr, "replica spectral fit: %s\n", msg.c_str());
        return kExitFailure;
    };
    const auto weights = parseWeights(o.weights);
    if (!weights) {
        return fail(weights.error().message);
    }
    const auto data = dataDir();
    auto obs = colour::loadCie1931(data);
    if (!obs) {
        return fail(obs.error().message);
    }
    auto d65 = spectral::loadCieIlluminant(data, "D65");
    if (!d65) {
        return fail(d65.error().message);
    }
    auto training = loadTraining(data, o.reflectances);
    if (!training) {
        return fail(training.error().message);
    }
    const auto lightNames =
            o.lights.empty() ? spectral::evaluationLightNames() : splitList(o.lights);
    // replica_k6: every training light, weighted as --weights says; general_k6: all equal.
    spectral::BasisFitOptions boothOptions;
    auto lights = loadFitLights(data, lightNames, *weights, boothOptions.lightWeights);
    if (!lights) {
        return fail(lights.error().message);
    }
    const std::filesystem::path outDir =
            o.out.empty() ? data / "channels" : std::filesystem::path(o.out);
    if (auto ok = checkOutDir(outDir); !ok) {
        return fail(ok.error().message);
    }
    const std::string provenance = fmt::format(
            "fitted by 'replica spectral fit' on {} reflectances ({}) and {} lights "
            "({}); working grid "
            "380-730 nm at 10 nm; see docs/accuracy.md",
            training->size(), o.reflectances, lightNames.size(), fmt::join(lightNames, " "));
    auto k6 = spectral::fitChannelBasis(*obs, *d65, *training, *lights, boothOptions, "replica_k6");
    if (!k6) {
        return fail(k6.error().message);
    }
    auto general = spectral::fitChannelBasis(*obs, *d65, *training, *lights,
                                             spectral::BasisFitOptions{}, "general_k6");
    if (!general) {
        return fail(general.error().message);
    }
    spectral::BasisFitOptions pca;
    pca.lightAware = false;
    auto pca6 = spectral::fitChannelBasis(*obs, *d65, *training, *lights, pca, "pca6");
    if (!pca6) {
        return fail(pca6.error().message);
    }
    spectral::SixChannelFitReport report;
    auto paper6 = fitPaperSix(*obs, *d65, *training, *lights, o.rounds, report);
    if (!paper6) {
        return fail(paper6.error().message);
    }
    const std::string boothNote = fmt::format("; light weights {} (others 1)", o.weights);
    const std::tuple<const colour::ChannelBasis*, const char*, std::string> outputs[] = {
            {&*k6, "replica_k6.csv", boothNote},
            {&*general, "general_k6.csv", ""},
            {&*pca6, "pca6.csv", "; principal components, lights unused"}};
    for (const auto& [basis, file, note] : outputs) {
        auto saved = colour::saveChannelBasis(*basis, outDir / file, provenance + note);
        if (!saved) {
            return fail(saved.error().message);
        }
        std::cout << "wrote " << (outDir / file).string() << "\n";
    }
    auto saved = spectral::saveSixChannelModel(
            *paper6, outDir / "paper6.csv",
            provenance + fmt::format("; {} alternating least-squares rounds", o.rounds));
    if (!saved) {
        return fail(saved.error().message);
    }
    std::cout << "wrote " << (outDir / "paper6.csv").string()
              << " and paper6_to_xyz.csv (objective "
              << fmt::format("{:.4g} -> {:.4g}",
                             report.objective.empty() ? 0.0 : report.objective.front(),
                             report.objective.empty() ? 0.0 : report.objective.back())
              << ")\n";
    return kExitOk;
}

} // namespace replica::platform
