// A plain additive display model (primaries matrix, black level, power-law tone response) used
// until a characterised profile is loaded: XYZ = black + M * rgb^gamma, rgb in [0, 1].
#pragma once

#include <glm/mat3x3.hpp>
#include <glm/vec3.hpp>

namespace replica::pipeline::render {

struct SimpleDisplay {
    glm::dmat3 rgbToXyz{1.0}; // columns: XYZ (cd/m^2) of full red, green, blue above black
    glm::dvec3 blackXyz{0.0};
    double gamma = 2.2;
};

// sRGB primaries and D65 white at peakWhiteCdM2, with a black of blackCdM2 at the white's
// chromaticity.
SimpleDisplay srgbLikeDisplay(double peakWhiteCdM2, double blackCdM2);

// Pixel drive values in [0, 1] (before quantisation) for an absolute XYZ; out-of-range channels
// clip.
glm::dvec3 simpleDisplayInverse(const SimpleDisplay& d, const glm::dvec3& xyz);

} // namespace replica::pipeline::render
