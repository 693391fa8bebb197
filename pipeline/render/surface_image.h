// A surface's diffuse reflectance as per-texel channel coefficients (the paper's two RGB float
// images).
#pragma once

#include <string>
#include <vector>

#include <pipeline/base/expected.h>
#include <pipeline/colour/channel_basis.h>

namespace replica::pipeline::render {

struct SurfaceImage {
    int width = 0;
    int height = 0;
    // Row-major from the bottom row up (GL texture order), kChannels floats per texel.
    std::vector<float> coeffs;
};

// A ColorChecker Classic (6 x 4 patches in chart order, top-left dark skin) with black gaps, from
// the BabelColor average spectra in dataDir/spectra, projected onto the basis.
Expected<SurfaceImage> makeColorCheckerSurface(const std::string& dataDir,
                                               const colour::ChannelBasis& basis,
                                               int width,
                                               int height);

} // namespace replica::pipeline::render
