// Hue-keeping gamut mapping in the display's linear (r) space, with per-class counters.
//
// Method (closed form per pixel, docs/display.md): (1) a colour brighter than peak white is scaled
// down to peak white's luminance, keeping its chromaticity ("over peak"); (2) a colour below the
// display black's luminance is shown as black ("below black": negative light after flare
// subtraction, rendering-notes hard case 16); (3) otherwise, if some r_c < 0 (a chromaticity
// outside the primaries' triangle), the colour moves along the straight line in r-space towards the
// display's neutral of the same luminance, g = s (1, 1, 1) with s = (Y - Y_k) / (Y_w - Y_k), to the
// first point with no negative channel: dominant wavelength (hue to first order) and luminance are
// kept, only purity drops; (4) if then some r_c > 1 (a reachable chromaticity too bright for the
// panel there), r is scaled down to max r_c = 1: chromaticity above black is kept, only luminance
// drops. (3) and (4) are "chroma". Per-channel clipping, kept for comparison, keeps neither.
#pragma once

#include <cstdint>

#include <glm/mat3x3.hpp>
#include <glm/vec3.hpp>

namespace replica::pipeline::display {

enum class GamutClass : std::uint8_t { InGamut = 0, Chroma = 1, OverPeak = 2, BelowBlack = 3 };

enum class GamutMode {
    HueKeeping, // the method above
    Clip,       // per-channel clip of r to [0, 1]; classes are still reported
};

struct GamutCounters {
    std::uint64_t pixels = 0;
    std::uint64_t chroma = 0;
    std::uint64_t overPeak = 0;
    std::uint64_t belowBlack = 0;

    // The same classes counted over the surface's pixels only (the rectangle a booth surface
    // covers; the black panel around it is below black by construction and says nothing about the
    // booth and the display). surfacePixels 0: no surface rectangle (a bare display pass): the
    // whole frame is the surface.
    std::uint64_t surfacePixels = 0;
    std::uint64_t surfaceChroma = 0;
    std::uint64_t surfaceOverPeak = 0;
    std::uint64_t surfaceBelowBlack = 0;

    void add(GamutClass c);
    std::uint64_t outOfGamut() const { return chroma + overPeak + belowBlack; }
    double outOfGamutFraction() const;
    // Out of gamut over the surface's pixels (the whole frame's fraction without a surface).
    double surfaceOutOfGamutFraction() const;
    // Above the panel's peak over the surface's pixels (likewise).
    double surfaceOverPeakFraction() const;
};

struct MappedLinear {
    glm::dvec3 r{0.0}; // in [0, 1]^3
    GamutClass gamutClass = GamutClass::InGamut;
};

// The geometry the mapping needs, cached from a display model.
struct GamutGeometry {
    glm::dmat3 xyzToLinear{1.0}; // M^-1
    glm::dvec3 blackXyz{0.0};
    double blackY = 0.0;
    double whiteY = 1.0;
    // DisplayModel::gamutEdgeTolerance: within it of the gamut (below 0: times the colour's largest
    // r; luminance: up to whiteY (1 + edgeTolerance)), r is clamped per channel instead of
    // mapped; the class is still the strict one.
    double edgeTolerance = 0.0;
    double edgeFloor = 0.0; // DisplayModel::gamutEdgeFloor
};

// Maps an absolute XYZ (cd/m^2) into the display gamut. Non-finite input maps to black and counts
// as below black. 'tolerance' is how far outside [0, 1] an r may be and still count as in gamut
// (then it is clamped), so that rounding in the matrix does not flag in-gamut colours; within the
// geometry's edgeTolerance the channels are clamped too, but the class stays Chroma or OverPeak.
MappedLinear
mapToGamut(const GamutGeometry& g, const glm::dvec3& xyz, GamutMode mode, double tolerance = 1e-9);

} // namespace replica::pipeline::display
