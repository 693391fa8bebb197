// The stand-in display model.
#include <algorithm>
#include <cmath>

#include <glm/matrix.hpp>

#include <pipeline/render/simple_display.h>

namespace replica::pipeline::render {

SimpleDisplay srgbLikeDisplay(double peakWhiteCdM2, double blackCdM2)
{
    // IEC 61966-2-1 linear sRGB to XYZ (D65, white Y = 1); GLM matrices are column-major.
    const glm::dmat3 srgb{0.4124, 0.2126, 0.0193, 0.3576, 0.7152, 0.1192, 0.1805, 0.0722, 0.9505};
    SimpleDisplay d;
    d.rgbToXyz = srgb * (peakWhiteCdM2 - blackCdM2);
    d.blackXyz = glm::dvec3{0.9505, 1.0, 1.0890} * blackCdM2;
    return d;
}

glm::dvec3 simpleDisplayInverse(const SimpleDisplay& d, const glm::dvec3& xyz)
{
    const glm::dvec3 linear = glm::inverse(d.rgbToXyz) * (xyz - d.blackXyz);
    glm::dvec3 out;
    for (int c = 0; c < 3; ++c) {
        out[c] = std::pow(std::clamp(linear[c], 0.0, 1.0), 1.0 / d.gamma);
    }
    return out;
}

} // namespace replica::pipeline::render
