// Loading the shipped reflectance sets and CIE illuminants.
#include <cmath>

#include <fmt/format.h>

#include <pipeline/colour/spectral_table.h>
#include <pipeline/csv/csv_cells.h>
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

namespace {

// Every column of a read table on the working grid, with its name.
Expected<NamedSpectra> namedSpectra(const colour::SpectralTable& table,
                                    const std::filesystem::path& path,
                                    colour::GridSampling sampling)
{
    auto spectra = table.allSpectra(sampling);
    if (!spectra) {
        return tl::unexpected(spectra.error());
    }
    return NamedSpectra{path.string(), table.columns, std::move(*spectra)};
}

} // namespace

Expected<NamedSpectra> loadNamedSpectra(const std::filesystem::path& path,
                                        colour::GridSampling sampling)
{
    auto table = colour::loadSpectralCsv(path);
    if (!table) {
        return tl::unexpected(table.error());
    }
    return namedSpectra(*table, path, sampling);
}

Expected<NamedSpectra> loadReflectances(const std::filesystem::path& path)
{
    auto table = colour::loadSpectralCsv(path);
    if (!table) {
        return tl::unexpected(table.error());
    }
    for (std::size_t i = 0; i < table->rows.size(); ++i) {
        for (std::size_t c = 0; c < table->columns.size(); ++c) {
            const double v = table->rows[i][c];
            if (v >= kMinReflectance && v <= kMaxReflectance) {
                continue;
            }
            return makeError(ErrorCode::InvalidArgument,
                             fmt::format("{}:{}: column '{}' value {:g} is no reflectance (a "
                                         "fraction of the light, {} to {}: a little below 0 is "
                                         "noise, above 1 a fluorescent sample); fix the value",
                                         path.string(), table->rowLines[i],
                                         csv::shownCell(table->columns[c]), v, kMinReflectance,
                                         kMaxReflectance));
        }
    }
    return namedSpectra(*table, path, colour::GridSampling::AtBandCentre);
}

Expected<void>
checkLightScale(const colour::Observer& obs, const Spectrum& light, const std::string& file)
{
    const colour::Xyz xyz = colour::spectrumToXyz(obs, light);
    if (!std::isfinite(xyz.x) || !std::isfinite(xyz.y) || !std::isfinite(xyz.z) ||
        xyz.y > kMaxLightY) {
        return makeError(ErrorCode::InvalidArgument,
                         fmt::format("{}: the light's values overflow: its XYZ is not finite or "
                                     "beyond {:g}; give the spectrum in smaller units (e.g. 100 at "
                                     "560 nm)",
                                     file, kMaxLightY));
    }
    if (light.max() > 0.0 && xyz.y < kMinLightY) {
        return makeError(ErrorCode::InvalidArgument,
                         fmt::format("{}: the light's values underflow: its Y is {:g}, zero or "
                                     "next to it; give the spectrum in larger units (e.g. 100 at "
                                     "560 nm)",
                                     file, xyz.y));
    }
    if (!(xyz.y > 0.0)) {
        return makeError(
                ErrorCode::InvalidArgument,
                fmt::format("{}: the light has no luminance over 380-730 nm (Y <= 0)", file));
    }
    // Power is not negative; a measured spectrum's dark-subtracted noise dips a little below 0.
    const double peak = light.max();
    for (std::size_t b = 0; b < colour::kBands; ++b) {
        if (light[b] < -kMaxNegativeLightFraction * peak) {
            return makeError(ErrorCode::InvalidArgument,
                             fmt::format("{}: the light's band at {:g} nm is {:g}, {:.1f} % of its "
                                         "peak below 0; a light's power cannot be negative (more "
                                         "than {:g} % is not noise): check the file",
                                         file, colour::bandCentreNm(b), light[b],
                                         -100.0 * light[b] / peak,
                                         100.0 * kMaxNegativeLightFraction));
        }
    }
    return {};
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
            return loadReflectances(dataDir / "spectra" / s.file);
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
