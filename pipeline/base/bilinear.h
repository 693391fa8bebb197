// The one bilinear rule every texel-grid lookup on the CPU uses: height field, normal map, horizon
// map and the luminance mip chain.
#pragma once

#include <cmath>

namespace replica::pipeline {

// Bilinear interpolation at a fractional texel position (texel centres at x + 0.5) of the values
// at(ix, iy) returns for the four texels around it. Edges are at's business: it clamps, returns a
// border value, or neither, as its map needs.
template <typename At>
auto bilinearAtTexel(double x, double y, const At& at)
{
    const double fx = x - 0.5;
    const double fy = y - 0.5;
    const double x0 = std::floor(fx);
    const double y0 = std::floor(fy);
    const double ax = fx - x0;
    const double ay = fy - y0;
    const int ix = static_cast<int>(x0);
    const int iy = static_cast<int>(y0);
    return (1.0 - ay) * ((1.0 - ax) * at(ix, iy) + ax * at(ix + 1, iy)) +
           ay * ((1.0 - ax) * at(ix, iy + 1) + ax * at(ix + 1, iy + 1));
}

} // namespace replica::pipeline
