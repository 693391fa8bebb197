// CAT02 chromatic adaptation (the transform of CIECAM02, CIE 159:2004) with a degree of adaptation
// D.
#pragma once

#include <pipeline/colour/matrix3.h>
#include <pipeline/colour/xyz.h>

namespace replica::pipeline::colour {

// The CAT02 forward matrix (XYZ to sharpened RGB) and its inverse.
const Matrix3& cat02Forward();
const Matrix3& cat02Inverse();

// The matrix adapting colours seen under sourceWhite to destinationWhite: M^-1 diag(D * rw_d / rw_s
// + 1 - D) M, the von Kries scaling in CAT02 space. Whites on any common scale (Y = 1 or 100); D =
// 1 is full adaptation. Whites with a non-positive sharpened component give the identity.
Matrix3
cat02AdaptationMatrix(const Xyz& sourceWhite, const Xyz& destinationWhite, double degree = 1.0);

Xyz cat02Adapt(const Xyz& xyz,
               const Xyz& sourceWhite,
               const Xyz& destinationWhite,
               double degree = 1.0);

} // namespace replica::pipeline::colour
