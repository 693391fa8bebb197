// CAT02 chromatic adaptation (the transform of CIECAM02, CIE 159:2004) with a degree of adaptation
// D.
#pragma once

#include <pipeline/colour/matrix3.h>
#include <pipeline/colour/xyz.h>

namespace replica::pipeline::colour {

// The CAT02 forward matrix (XYZ to sharpened RGB) and its inverse.
const Matrix3& cat02Forward();
const Matrix3& cat02Inverse();

// Whether CAT02 can adapt from this white: its three sharpened (CAT02 RGB) responses are positive.
// A narrow-band light's are not (a 450 nm line has R < 0: the sharpened primaries are not
// colours), and the von Kries ratio would flip or blow up.
bool cat02Defined(const Xyz& white);

// How cat02AdaptationMatrix adapts from one white to another: CAT02; where CAT02 is undefined for
// either, von Kries scaling in XYZ; and where even an XYZ component is not positive (a light at
// 650-730 nm, where the observer's z-bar is 0, excites no Z), nothing: the identity.
enum class Adaptation { Cat02, XyzScaling, None };
Adaptation adaptationBetween(const Xyz& sourceWhite, const Xyz& destinationWhite);

// The matrix adapting colours seen under sourceWhite to destinationWhite: M^-1 diag(D * rw_d / rw_s
// + 1 - D) M, the von Kries scaling in CAT02 space. Whites on any common scale (Y = 1 or 100); D =
// 1 is full adaptation. Where CAT02 is undefined for either white (cat02Defined), the same scaling
// in XYZ (the source white still lands on the destination's, so a neutral stays neutral), and the
// identity only where even an XYZ component is not positive.
Matrix3
cat02AdaptationMatrix(const Xyz& sourceWhite, const Xyz& destinationWhite, double degree = 1.0);

Xyz cat02Adapt(const Xyz& xyz,
               const Xyz& sourceWhite,
               const Xyz& destinationWhite,
               double degree = 1.0);

} // namespace replica::pipeline::colour
