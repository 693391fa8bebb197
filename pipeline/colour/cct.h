// Correlated colour temperature and Duv of a light: the nearest point of the Planckian locus in the
// CIE 1960 (u, v) diagram, found by direct minimisation on the observer in hand.
#pragma once

#include <pipeline/base/expected.h>
#include <pipeline/colour/spectrum.h>
#include <pipeline/colour/xyz.h>

namespace replica::pipeline::colour {

// Second radiation constant (CODATA, as used by CIE 015:2018 for the Planckian locus), m K.
constexpr double kPlanckC2 = 1.438776877e-2;

// Relative spectral radiance of a Planckian radiator at temperatureK on the working grid, scaled to
// 1 at 560 nm.
Spectrum planckianSpectrum(double temperatureK);

struct Cct {
    double kelvin = 0.0;
    double duv = 0.0; // signed distance from the locus in (u, v); positive above it (greenish)
};

// CIE 1960 UCS chromaticity.
struct Uv {
    double u = 0.0, v = 0.0;
};
Uv xyzToUv1960(const Xyz& xyz);

// CCT of a colour (normally the XYZ of a light on the same observer). The locus is computed from
// the observer's own colour-matching functions, so that a Planckian spectrum on the working grid
// returns its own temperature; CCT is searched in 1000..100000 K. Fails for black, for
// chromaticities farther than 0.05 from the locus (CCT is not defined there, CIE 015:2018 9.5) and
// outside the range.
Expected<Cct> correlatedColourTemperature(const Observer& obs, const Xyz& xyz);

} // namespace replica::pipeline::colour
