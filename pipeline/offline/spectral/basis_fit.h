// Fitting representation (3): a K = 6 channel basis whose per-light matrix is recomputed for the
// light actually present.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include <pipeline/base/expected.h>
#include <pipeline/colour/channel_basis.h>
#include <pipeline/spectral/light_weights.h>
#include <pipeline/spectral/reference_sets.h>
#include <pipeline/spectral/representation.h>

namespace replica::pipeline::spectral {

struct BasisFitOptions {
    // true: choose the 6-dimensional coefficient space that best predicts the colour of the
    // training reflectances under every training light (a generalised eigenproblem, below); false:
    // plain (uncentred) principal components of the reflectances.
    bool lightAware = true;
    // Weight errors as CIELAB does (fit_metric.h); false: plain XYZ errors.
    bool perceptual = true;
    // Tikhonov term added to the reflectance second moment, relative to its mean diagonal: keeps
    // the projection smooth where the training set has no energy.
    double ridge = 1e-4;
    // Weight of each training light in the sum over lights (empty: all 1). With K = 6 channels at
    // most two lights can be exact at once; weighting the booth's own lamps well above the others
    // makes them nearly exact while keeping the rest usable (docs/accuracy.md).
    std::vector<double> lightWeights;
};

// With C the weighted second moment of the training reflectances (plus the ridge) and G the stacked
// H_j A_j of the training lights, the K-dimensional projection P minimising
//     sum_j sum_i w_i^2 || H_j (A_j r_i - M_j P r_i) ||^2,  M_j the best matrix for light j,
// has rows spanning the top generalised eigenvectors of (C G^T G C, C). With C = L L^T these are
// p = L^-T q for the top eigenvectors q of L^T G^T G L, and the best M_j is A_j W with the
// light-free reconstruction W = C P^T (P C P^T)^-1 = L Q. So M_j is exactly channelToXyz(basis,
// light).
Expected<colour::ChannelBasis> fitChannelBasis(const Observer& obs,
                                               const Spectrum& d65,
                                               const NamedSpectra& reflectances,
                                               const NamedSpectra& lights,
                                               const BasisFitOptions& options,
                                               const std::string& name);

} // namespace replica::pipeline::spectral
