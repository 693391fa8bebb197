// The error metric the channel fits minimise: XYZ errors under each training light, mapped to an
// approximately CIELAB-uniform space, with darker samples weighted up as CIELAB's cube root does.
#pragma once

#include <vector>

#include <pipeline/spectral/dense_matrix.h>
#include <pipeline/spectral/reference_sets.h>
#include <pipeline/spectral/representation.h>

namespace replica::pipeline::spectral {

// One training light: A maps a reflectance (36 bands) to XYZ under the light scaled to Y = 1, and H
// maps an XYZ error under that light to an approximate CIELAB error after CAT02 to D65: the
// Jacobian of (L*, a*, b*) at the white's cube-root slope, J diag(1 / white_D65) CAT02(light ->
// D65), with J = [[0, 116, 0], [500, -500, 0], [0, 200, -200]] / 3. Without perceptual weighting H
// is I.
struct FitLight {
    Spectrum spectrum; // scaled to Y = 1
    DenseMatrix a;     // 3 x 36
    DenseMatrix h;     // 3 x 3
};

std::vector<FitLight> makeFitLights(const Observer& obs,
                                    const Spectrum& d65,
                                    const NamedSpectra& lights,
                                    bool perceptual);

// Per-sample weights: the slope of CIELAB's f(Y) at the sample's Y under equal energy (relative to
// the slope at Y = 0.2), or all 1 without perceptual weighting. Dark samples count for more, as
// their CIELAB error per unit of XYZ error is larger.
std::vector<double>
sampleWeights(const Observer& obs, const NamedSpectra& reflectances, bool perceptual);

// C = sum_i w_i^2 r_i r_i^T / N (36 x 36), the weighted second moment of the training reflectances.
DenseMatrix weightedSecondMoment(const NamedSpectra& reflectances,
                                 const std::vector<double>& weights);

} // namespace replica::pipeline::spectral
