// Loading the shipped reflectance sets and CIE illuminants.
#include <fmt/format.h>

#include <pipeline/colour/spectral_table.h>
#include <pipeline/spectral/reference_sets.h>

namespace replica::pipeline::spectral {
namespace {

struct SetFile {
    const char* name;
    const char* file;
};

constexpr SetFile kReflectanceSets[] = {
        {"colorchecker", "colorchecker24_babelcolor_avg_10nm_380_730.csv"},
        {"colorchecker-ohta", "colorchecker24_ohta_5nm_380_780.csv"},
        {"ces99", "cie2017_ces99_5nm_380_780.csv"},
        {"tcs14", "cie_tcs01_14_5nm_360_830.csv"},
};

constexpr const char* kIlluminantFiles[] = {
        "cie_illuminants_A_D50_D65_5nm_300_780.csv",
        "cie_illuminants_F1_F12_5nm_380_780.csv",
        "cie_illuminants_FL3_1_15_5nm_380_780.csv",
        "cie_illuminants_LED_5nm_380_780.csv",
};

} // namespace

void NamedSpectra::append(const NamedSpectra& other)
{
    names.insert(names.end(), other.names.begin(), other.names.end());
    spectra.insert(spectra.end(), other.spectra.begin(), other.spectra.end());
}

Expected<NamedSpectra> loadNamedSpectra(const std::filesystem::path& path,
                                        colour::GridSampling sampling)
{
    auto table = colour::loadSpectralCsv(path);
    if (!table) {
        return tl::unexpected(table.error());
    }
    auto spectra = table->allSpectra(sampling);
    if (!spectra) {
        return tl::unexpected(spectra.error());
    }
    return NamedSpectra{path.string(), table->columns, std::move(*spectra)};
}

std::vector<std::string> reflectanceSetNames()
{
    std::vector<std::string> names;
    for (const auto& s : kReflectanceSets) {
        names.emplace_back(s.name);
    }
    return names;
}

Expected<NamedSpectra> loadReflectanceSet(const std::filesystem::path& dataDir,
                                          const std::string& name)
{
    for (const auto& s : kReflectanceSets) {
        if (name == s.name) {
            return loadNamedSpectra(dataDir / "spectra" / s.file,
                                    colour::GridSampling::AtBandCentre);
        }
    }
    return makeError(ErrorCode::NotFound,
                     fmt::format("no reflectance set named '{}' (known: {})", name,
                                 fmt::join(reflectanceSetNames(), ", ")));
}

Expected<NamedSpectra> loadAllCieIlluminants(const std::filesystem::path& dataDir)
{
    NamedSpectra all;
    all.source = (dataDir / "spectra").string();
    for (const char* file : kIlluminantFiles) {
        auto set = loadNamedSpectra(dataDir / "spectra" / file, colour::GridSampling::BandAverage);
        if (!set) {
            return tl::unexpected(set.error());
        }
        all.append(*set);
    }
    return all;
}

Expected<Spectrum> loadCieIlluminant(const std::filesystem::path& dataDir, const std::string& name)
{
    for (const char* file : kIlluminantFiles) {
        auto table = colour::loadSpectralCsv(dataDir / "spectra" / file);
        if (!table) {
            return tl::unexpected(table.error());
        }
        for (const auto& column : table->columns) {
            if (column == name) {
                return table->spectrum(name, colour::GridSampling::BandAverage);
            }
        }
    }
    return makeError(ErrorCode::NotFound, fmt::format("no CIE illuminant named '{}' in {}", name,
                                                      (dataDir / "spectra").string()));
}

std::vector<std::string> evaluationLightNames()
{
    return {"A", "D50", "D65", "F2", "F7", "F8", "F11", "LED-B4"};
}

} // namespace replica::pipeline::spectral
