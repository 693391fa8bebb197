// Building the ColorChecker surface image.
#include <filesystem>

#include <pipeline/colour/spectral_table.h>
#include <pipeline/render/surface_image.h>

namespace replica::pipeline::render {

Expected<SurfaceImage> makeColorCheckerSurface(const std::string& dataDir,
                                               const colour::ChannelBasis& basis,
                                               int width,
                                               int height)
{
    auto table = colour::loadSpectralCsv(std::filesystem::path(dataDir) / "spectra" /
                                         "colorchecker24_babelcolor_avg_10nm_380_730.csv");
    if (!table) {
        return tl::unexpected(table.error());
    }
    auto spectra = table->allSpectra();
    if (!spectra) {
        return tl::unexpected(spectra.error());
    }
    if (spectra->size() != 24) {
        return makeError(ErrorCode::Corrupt,
                         table->source + ": expected the 24 ColorChecker patches");
    }
    std::vector<colour::ChannelCoeffs> patch;
    for (const auto& s : *spectra) {
        patch.push_back(colour::projectReflectance(basis, s));
    }
    // The chart's frame: a near-black card (reflectance 0.03 everywhere).
    const colour::ChannelCoeffs frame =
            colour::projectReflectance(basis, colour::Spectrum::constant(0.03));

    SurfaceImage img;
    img.width = width;
    img.height = height;
    img.coeffs.resize(static_cast<std::size_t>(width) * static_cast<std::size_t>(height) *
                      colour::kChannels);
    constexpr int kCols = 6;
    constexpr int kRows = 4;
    constexpr double kGap = 0.12; // fraction of a cell left as frame on each side
    for (int y = 0; y < height; ++y) {
        const double v = 1.0 - (y + 0.5) / height; // 0 at the top of the chart
        const int row = static_cast<int>(v * kRows);
        const double fy = v * kRows - row;
        for (int x = 0; x < width; ++x) {
            const double u = (x + 0.5) / width;
            const int col = static_cast<int>(u * kCols);
            const double fx = u * kCols - col;
            const bool inPatch = fx > kGap && fx < 1.0 - kGap && fy > kGap && fy < 1.0 - kGap;
            const auto& c = inPatch ? patch[static_cast<std::size_t>(row * kCols + col)] : frame;
            float* out =
                    &img.coeffs[(static_cast<std::size_t>(y) * static_cast<std::size_t>(width) +
                                 static_cast<std::size_t>(x)) *
                                colour::kChannels];
            for (std::size_t k = 0; k < colour::kChannels; ++k) {
                out[k] = static_cast<float>(c[k]);
            }
        }
    }
    return img;
}

} // namespace replica::pipeline::render
