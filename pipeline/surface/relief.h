// Small-scale geometry of a surface: height field (metres), its normal map and Sloan & Cohen
// horizon map.
#pragma once

#include <cmath>
#include <numbers>
#include <vector>

#include <glm/vec3.hpp>

namespace replica::pipeline::surface {

using Vec3 = glm::dvec3;

// Tangent frame of the surface: +x along image columns, +y up the image (against row order), +z out
// of the surface towards the viewer. Heights are in metres, texel pitch in metres.
struct HeightField {
    int width = 0;
    int height = 0;
    double pitchM = 1e-3;
    std::vector<double> m; // row-major, row 0 at the top

    double at(int x, int y) const; // clamped to the edge
    // Bilinear at texel coordinates (texel centres at x + 0.5).
    double sample(double x, double y) const;
    bool flat() const;
};

// Central differences over 2 pitches (one-sided at the edges), renormalised; a vertical cliff gives
// a finite, nearly horizontal normal and never normalises a zero vector.
std::vector<Vec3> normalMap(const HeightField& h);

// The largest angle (radians) between the normals of two texels side by side or one above the
// other in normalMap(h): how fast the surface turns per texel where it turns fastest. 0 on a
// plane, flat or tilted.
double largestNormalTurn(const HeightField& h);

// A horizon table of n entries at azimuths 2 pi k / n (k = 0 along +x, n/4 along +y), linear in
// azimuth, at the direction whose components along x and y are (lx, ly): the one rule the horizon
// map and the exact reference's horizon tests read a table by.
template <typename T>
double atAzimuth(const T* table, int n, double lx, double ly)
{
    double phi = std::atan2(ly, lx); // atan2(0, 0) = 0: defined for a light straight overhead
    if (phi < 0.0) {
        phi += 2.0 * std::numbers::pi;
    }
    const double f = phi / (2.0 * std::numbers::pi) * n;
    const int k0 = static_cast<int>(std::floor(f)) % n;
    const int k1 = (k0 + 1) % n;
    const double t = f - std::floor(f);
    return (1.0 - t) * table[k0] + t * table[k1];
}

// Horizon map: for each texel and k azimuths phi_k = 2 pi k / K (phi = 0 along +x, pi/2 along +y),
// the sine of the highest occluder's elevation, floored at 0 (the macro plane's own horizon).
// Marching reaches maxDistanceM.
struct HorizonMap {
    int width = 0;
    int height = 0;
    int directions = 0;
    std::vector<float> sinBeta; // [(y * width + x) * directions + k]

    // Interpolated linearly in azimuth; l is a tangent-space unit direction.
    double sinHorizon(int x, int y, const Vec3& l) const;
    // At a fractional texel position (texel centres at x + 0.5): bilinear between the four texels
    // around it (clamped to the edge, as the normal map is read), each interpolated in azimuth.
    double sinHorizonBilinear(double x, double y, const Vec3& l) const;
};

HorizonMap horizonMap(const HeightField& h, int directions, double maxDistanceM);

// The map with every sine rounded to the nearest half float (IEEE binary16, ties away from zero):
// within 2^-12 of the float, and exactly what the GL pass stores when it packs eight directions
// into one texel (shading::PreparedScene::horizonHalf), so that the CPU model reads the same.
HorizonMap halfPrecision(const HorizonMap& map);

// The exact horizon at a fractional texel position and azimuth, by marching the bilinear height
// field in steps of half a pitch: what the reference uses.
double exactSinHorizon(const HeightField& h, double x, double y, double phi, double maxDistanceM);

} // namespace replica::pipeline::surface
