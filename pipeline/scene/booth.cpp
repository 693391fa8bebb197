// The shipped booth and its simplest point-light decomposition.
#include <algorithm>
#include <filesystem>

#include <fmt/format.h>

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
    // One geometry for the whole appliance: the lamps share one emitter (the booth model's
    // ceiling), each drawn from its own light.
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
        auto s = table->spectrum(light.referenceColumn, colour::GridSampling::BandAverage);
        if (!s) {
            return tl::unexpected(s.error());
        }
        light.referenceSpectrum = *s;
    }
    placeBoothWalls(b);
    return b;
}

void placeBoothWalls(booth::Booth& b, const StandModel& stand)
{
    if (b.walls && !b.lights.empty()) {
        const colour::Spectrum reflectance = b.walls->reflectance;
        b.walls = defaultBoothWalls(b.ceiling(), stand);
        b.walls->reflectance = reflectance;
    }
}

booth::BoothWalls defaultBoothWalls(const booth::BoothLight& ceiling, const StandModel& stand)
{
    return booth::defaultWalls(ceiling,
                               stand.hingeM.z - stand.hingeToPanelM - stand.panelHeightM - 0.05);
}

} // namespace replica::pipeline::scene
