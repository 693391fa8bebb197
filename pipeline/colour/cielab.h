// CIE xyY and CIELAB (CIE 015:2018) with the exact constants epsilon = 216/24389, kappa = 24389/27.
#pragma once

#include <string>

#include <pipeline/colour/xyz.h>

namespace replica::pipeline::colour {

struct XyY {
    double x = 0.0, y = 0.0, Y = 0.0;
};

struct Lab {
    double L = 0.0, a = 0.0, b = 0.0;
    std::string toString() const;
};

constexpr double kLabEpsilon = 216.0 / 24389.0; // (6/29)^3: where the cube root meets the line
constexpr double kLabKappa = 24389.0 / 27.0;    // (29/3)^3: slope of the line, in L* per unit Y/Yn

// xyY of a colour. Black (X+Y+Z = 0) has no chromaticity: it takes 'chromaticityOfBlack', by
// convention the white point's, so that a black-to-white ramp has one chromaticity.
XyY xyzToXyY(const Xyz& xyz, const Xyz& chromaticityOfBlack);
// Inverse of xyzToXyY; y = 0 (not a real colour) gives black.
Xyz xyYToXyz(const XyY& xyy);

// CIELAB relative to a white with Y > 0 (same scale as xyz: Y = 1 or Y = 100 alike).
Lab xyzToLab(const Xyz& xyz, const Xyz& white);
Xyz labToXyz(const Lab& lab, const Xyz& white);

} // namespace replica::pipeline::colour
