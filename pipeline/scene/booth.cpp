// The shipped booth and its simplest point-light decomposition.
#include <algorithm>
#include <filesystem>

#include <fmt/format.h>
#include <glm/geometric.hpp>

#include <pipeline/booth/booth_model.h>
#include <pipeline/booth/lamp_kinds.h>
#include <pipeline/colour/spectral_table.h>
#include <pipeline/scene/booth.h>

namespace replica::pipeline::scene {
using booth::kLampKinds;
using booth::LampKind;

Expected<booth::Booth> loadDefaultBooth(const std::string& dataDir)
{
    return loadApplianceBooth(std::filesystem::path(dataDir) / "booth", dataDir);
}

Expected<booth::Booth> loadApplianceBooth(const std::filesystem::path& boothDir,
                                          const std::string& dataDir)
{
    const auto boothFile = (boothDir / "booth.json").string();
    auto model = booth::loadBooth(boothDir);
    if (!model) {
        return tl::unexpected(model.error());
    }
    if (model->lights.empty()) {
        return makeError(ErrorCode::Corrupt,
                         fmt::format("{}: the booth model has no lights", boothDir.string()));
    }
    booth::Booth b = std::move(*model);
    b.id = "replica-booth-1";
    // One geometry for the whole appliance: the flat renderer and pass 2 light the surface from
    // the first light's ceiling, the booth renderer from every light's own.
    const booth::BoothLight& first = b.ceiling();
    for (const auto& l : b.lights) {
        if (l.centre != first.centre || l.edgeU != first.edgeU || l.edgeV != first.edgeV) {
            return makeError(ErrorCode::Corrupt,
                             fmt::format("{}: light '{}' has another ceiling than '{}'; the "
                                         "appliance's booth has one emitter for all its lamps",
                                         boothFile, l.name, first.name));
        }
    }
    for (auto& light : b.lights) {
        const auto kind = std::find_if(kLampKinds.begin(), kLampKinds.end(),
                                       [&](const LampKind& k) { return light.name == k.name; });
        if (kind == kLampKinds.end()) {
            std::string known;
            for (const auto& k : kLampKinds) {
                known += (known.empty() ? "" : ", ") + std::string(k.name);
            }
            return makeError(ErrorCode::Corrupt,
                             fmt::format("{}: light '{}' is not a lamp this build knows ({}); "
                                         "name each light after one of them",
                                         boothFile, light.name, known));
        }
        light.referenceFile = kind->file;
        light.referenceColumn = kind->column;
        light.nominalLuminanceCdM2 = kind->nominalLuminanceCdM2;
        auto table = colour::loadSpectralCsv(std::filesystem::path(dataDir) / "spectra" /
                                             light.referenceFile);
        if (!table) {
            return tl::unexpected(table.error());
        }
        auto s = table->spectrum(light.referenceColumn);
        if (!s) {
            return tl::unexpected(s.error());
        }
        light.referenceSpectrum = *s;
    }
    return b;
}

std::vector<booth::PointLight>
uniformGridLights(const booth::BoothLight& ceiling, double luminanceCdM2, int nu, int nv)
{
    std::vector<booth::PointLight> lights;
    if (nu <= 0 || nv <= 0) {
        return lights;
    }
    const double cellArea = glm::length(ceiling.edgeU) * glm::length(ceiling.edgeV) / (nu * nv);
    for (int j = 0; j < nv; ++j) {
        for (int i = 0; i < nu; ++i) {
            const double u = (i + 0.5) / nu - 0.5;
            const double v = (j + 0.5) / nv - 0.5;
            booth::PointLight l;
            l.position = ceiling.centre + u * ceiling.edgeU + v * ceiling.edgeV;
            l.intensityCd = luminanceCdM2 * cellArea;
            l.regionU = ceiling.edgeU / static_cast<double>(nu);
            l.regionV = ceiling.edgeV / static_cast<double>(nv);
            l.regionOrigin = l.position - 0.5 * l.regionU - 0.5 * l.regionV;
            l.meanCdM2 = luminanceCdM2;
            lights.push_back(l);
        }
    }
    return lights;
}

} // namespace replica::pipeline::scene
