// Channel bases and the per-light channel-to-XYZ matrix.
#include <algorithm>

#include <fmt/format.h>

#include <pipeline/base/output_file.h>
#include <pipeline/colour/channel_basis.h>
#include <pipeline/colour/spectral_table.h>

namespace replica::pipeline::colour {

ChannelBasis boxBasis()
{
    ChannelBasis b;
    b.name = "box6";
    constexpr std::size_t kPerBand =
            6; // 6 working bands per box; the last box gets the remaining 6
    for (std::size_t i = 0; i < kBands; ++i) {
        const std::size_t k = std::min(i / kPerBand, kChannels - 1);
        b.reconstruct[k][i] = 1.0;
    }
    for (std::size_t k = 0; k < kChannels; ++k) {
        const double n = b.reconstruct[k].sum();
        b.project[k] = b.reconstruct[k] * (1.0 / n);
    }
    return b;
}

ChannelCoeffs projectReflectance(const ChannelBasis& basis, const Spectrum& reflectance)
{
    ChannelCoeffs c{};
    for (std::size_t k = 0; k < kChannels; ++k) {
        c[k] = (basis.project[k] * reflectance).sum();
    }
    return c;
}

ChannelToXyz channelToXyz(const ChannelBasis& basis, const Observer& obs, const Spectrum& light)
{
    ChannelToXyz m{};
    const double lightY = spectrumToXyz(obs, light).y;
    if (!(lightY > 0.0)) {
        return m;
    }
    const Spectrum unitLight = light * (1.0 / lightY);
    for (std::size_t k = 0; k < kChannels; ++k) {
        m[k] = spectrumToXyz(obs, unitLight * basis.reconstruct[k]);
    }
    return m;
}

Expected<ChannelBasis> loadChannelBasis(const std::filesystem::path& path)
{
    auto table = loadSpectralCsv(path);
    if (!table) {
        return tl::unexpected(table.error());
    }
    auto grid = checkWorkingGrid(*table);
    if (!grid) {
        return tl::unexpected(grid.error());
    }
    ChannelBasis basis;
    basis.name = path.stem().string();
    for (std::size_t k = 0; k < kChannels; ++k) {
        auto p = workingGridColumn(*table, fmt::format("project_{}", k + 1));
        auto r = workingGridColumn(*table, fmt::format("reconstruct_{}", k + 1));
        if (!p || !r) {
            return tl::unexpected(!p ? p.error() : r.error());
        }
        basis.project[k] = *p;
        basis.reconstruct[k] = *r;
    }
    return basis;
}

Expected<void> saveChannelBasis(const ChannelBasis& basis,
                                const std::filesystem::path& path,
                                const std::string& provenance)
{
    std::string text = fmt::format("# Replica channel basis '{}': {}\n", basis.name, provenance);
    text += "wavelength_nm";
    for (std::size_t k = 0; k < kChannels; ++k) {
        text += fmt::format(",project_{}", k + 1);
    }
    for (std::size_t k = 0; k < kChannels; ++k) {
        text += fmt::format(",reconstruct_{}", k + 1);
    }
    text += "\n";
    for (std::size_t l = 0; l < kBands; ++l) {
        text += fmt::format("{}", bandCentreNm(l));
        for (std::size_t k = 0; k < kChannels; ++k) {
            text += fmt::format(",{:.17g}", basis.project[k][l]);
        }
        for (std::size_t k = 0; k < kChannels; ++k) {
            text += fmt::format(",{:.17g}", basis.reconstruct[k][l]);
        }
        text += "\n";
    }
    return writeOutputFile(path, text, "channel basis");
}

Expected<ChannelBasis> loadDefaultChannelBasis(const std::filesystem::path& dataDir)
{
    return loadChannelBasis(dataDir / "channels" / kDefaultChannelBasisFile);
}

} // namespace replica::pipeline::colour
