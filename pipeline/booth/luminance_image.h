// A light's spatial luminance image (cd/m^2 per texel) and its exact area-averaged mip chain.
#pragma once

#include <string>
#include <vector>

#include <pipeline/base/expected.h>

namespace replica::pipeline::booth {

// Row-major, x along the light's u edge, y along its v edge; texel (x, y) covers [x, x+1] x [y,
// y+1] in texel coordinates. Values are luminance in cd/m^2, double for the reference and the SATs.
struct LuminanceImage {
    int width = 0;
    int height = 0;
    std::vector<double> cdM2;

    static LuminanceImage filled(int w, int h, double value);
    double at(int x, int y) const { return cdM2[static_cast<std::size_t>(y) * width + x]; }
    double& at(int x, int y) { return cdM2[static_cast<std::size_t>(y) * width + x]; }
    double sum() const;
    double max() const;
};

// The brightest luminance a booth light's map may hold: the sun's disc at noon, about 1.6e9 cd/m^2.
// Nothing in a booth is brighter; a map that is comes in another unit or is damaged.
constexpr double kMaxLuminanceCdM2 = 1.6e9;

// Fails naming the first texel that is negative, NaN, Inf or brighter than kMaxLuminanceCdM2 (hard
// cases 7 and 18); 'what' names the source (file or light) in the message.
Expected<void> checkLuminance(const LuminanceImage& img, const std::string& what);

// Mip chain over the image padded with zeros to power-of-two sides (level 0 is padded too), so
// every coarser texel is the exact mean of four finer ones and power (mean x area) is conserved at
// every level. The light itself covers [0, usedU] x [0, usedV] of the padded texture's unit square.
struct MipChain {
    std::vector<LuminanceImage> levels;
    double usedU = 1.0;
    double usedV = 1.0;

    // Bilinear lookup at a (fractional) level, trilinear between levels, in the light's own uv in
    // [0,1]^2; zero outside (the dark booth), the same rule as a CLAMP_TO_BORDER texture with
    // border 0.
    double sample(double u, double v, double level) const;
    // Bilinear within the one level nearest 'level', GL_LINEAR_MIPMAP_NEAREST's rule: level 0 up
    // to 1/2, then ceil(level + 1/2) - 1, clamped to the chain; half the fetches of sample().
    double sampleNearestLevel(double u, double v, double level) const;
    int maxLevel() const { return static_cast<int>(levels.size()) - 1; }
};

MipChain buildMipChain(const LuminanceImage& img);

} // namespace replica::pipeline::booth
