// The shipped booth and its simplest point-light decomposition.
#include <filesystem>

#include <fmt/format.h>
#include <glm/geometric.hpp>

#include <pipeline/booth/booth_model.h>
#include <pipeline/colour/spectral_table.h>
#include <pipeline/scene/booth.h>

namespace replica::pipeline::scene {

Expected<Booth> loadDefaultBooth(const std::string& dataDir)
{
    Booth booth;
    booth.id = "replica-booth-1";
    booth.lamps = {
            {"tungsten", "cie_illuminants_A_D50_D65_5nm_300_780.csv", "A", 2200.0, {}},
            {"d50-fluorescent", "cie_illuminants_F1_F12_5nm_380_780.csv", "F8", 2600.0, {}},
            {"d65-fluorescent", "cie_illuminants_F1_F12_5nm_380_780.csv", "F7", 2600.0, {}},
    };
    for (auto& lamp : booth.lamps) {
        auto table = colour::loadSpectralCsv(std::filesystem::path(dataDir) / "spectra" /
                                             lamp.spectrumFile);
        if (!table) {
            return tl::unexpected(table.error());
        }
        auto s = table->spectrum(lamp.spectrumColumn);
        if (!s) {
            return tl::unexpected(s.error());
        }
        lamp.spectrum = *s;
    }
    // One geometry for the whole appliance: the ceiling of the booth model (data/booth), which
    // the booth renderer lights the surface with.
    const auto boothDir = std::filesystem::path(dataDir) / "booth";
    auto model = booth::loadBooth(boothDir);
    if (!model) {
        return tl::unexpected(model.error());
    }
    if (model->lights.empty()) {
        return makeError(ErrorCode::Corrupt,
                         fmt::format("{}: the booth model has no lights", boothDir.string()));
    }
    const booth::BoothLight& first = model->lights.front();
    for (const auto& l : model->lights) {
        if (l.centre != first.centre || l.edgeU != first.edgeU || l.edgeV != first.edgeV) {
            return makeError(ErrorCode::Corrupt,
                             fmt::format("{}: light '{}' has another ceiling than '{}'; the "
                                         "appliance's booth has one emitter for all its lamps",
                                         (boothDir / "booth.json").string(), l.name, first.name));
        }
    }
    booth.emitter.centreM = first.centre;
    booth.emitter.edgeUM = first.edgeU;
    booth.emitter.edgeVM = first.edgeV;
    booth.emitter.normal = first.normal();
    return booth;
}

std::vector<booth::PointLight>
uniformGridLights(const Emitter& e, double luminanceCdM2, int nu, int nv)
{
    std::vector<booth::PointLight> lights;
    if (nu <= 0 || nv <= 0) {
        return lights;
    }
    const double cellArea = glm::length(e.edgeUM) * glm::length(e.edgeVM) / (nu * nv);
    for (int j = 0; j < nv; ++j) {
        for (int i = 0; i < nu; ++i) {
            const double u = (i + 0.5) / nu - 0.5;
            const double v = (j + 0.5) / nv - 0.5;
            booth::PointLight l;
            l.position = e.centreM + u * e.edgeUM + v * e.edgeVM;
            l.intensityCd = luminanceCdM2 * cellArea;
            l.regionU = e.edgeUM / static_cast<double>(nu);
            l.regionV = e.edgeVM / static_cast<double>(nv);
            l.regionOrigin = l.position - 0.5 * l.regionU - 0.5 * l.regionV;
            l.meanCdM2 = luminanceCdM2;
            lights.push_back(l);
        }
    }
    return lights;
}

} // namespace replica::pipeline::scene
