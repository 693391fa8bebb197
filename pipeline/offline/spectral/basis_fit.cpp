// Light-aware and principal-component channel bases.
#include <fmt/format.h>

#include <pipeline/offline/spectral/basis_fit.h>
#include <pipeline/spectral/dense_matrix.h>
#include <pipeline/spectral/fit_metric.h>

namespace replica::pipeline::spectral {

using colour::kBands;
using colour::kChannels;

Expected<colour::ChannelBasis> fitChannelBasis(const Observer& obs,
                                               const Spectrum& d65,
                                               const NamedSpectra& reflectances,
                                               const NamedSpectra& lights,
                                               const BasisFitOptions& options,
                                               const std::string& name)
{
    if (reflectances.size() < kChannels) {
        return makeError(ErrorCode::InvalidArgument,
                         fmt::format("channel fit: needs at least {} training reflectances, got {}",
                                     kChannels, reflectances.size()));
    }
    const auto weights = sampleWeights(obs, reflectances, options.perceptual);
    DenseMatrix c = weightedSecondMoment(reflectances, weights);
    double trace = 0.0;
    for (std::size_t i = 0; i < kBands; ++i) {
        trace += c(i, i);
    }
    for (std::size_t i = 0; i < kBands; ++i) {
        c(i, i) += options.ridge * trace / static_cast<double>(kBands);
    }

    colour::ChannelBasis basis;
    basis.name = name;
    if (!options.lightAware) {
        const SymmetricEigen eig = symmetricEigen(c);
        for (std::size_t k = 0; k < kChannels; ++k) {
            double sign = 0.0;
            for (std::size_t l = 0; l < kBands; ++l) {
                sign += eig.vectors(l, k);
            }
            sign = sign < 0.0 ? -1.0 : 1.0;
            for (std::size_t l = 0; l < kBands; ++l) {
                basis.project[k][l] = sign * eig.vectors(l, k);
                basis.reconstruct[k][l] = sign * eig.vectors(l, k);
            }
        }
        return basis;
    }

    const auto fitLights = makeFitLights(obs, d65, lights, options.perceptual);
    if (fitLights.empty()) {
        return makeError(ErrorCode::InvalidArgument,
                         "channel fit: no training light has luminance");
    }
    auto l = cholesky(c);
    if (!l) {
        return tl::unexpected(l.error());
    }
    const DenseMatrix linvT = invertLowerTriangular(*l).transposed();
    std::vector<DenseMatrix> g;
    for (const auto& f : fitLights) {
        g.push_back(f.h * f.a);
    }
    if (fitLights.size() != lights.size()) {
        return makeError(ErrorCode::InvalidArgument,
                         "channel fit: a training light has no luminance");
    }
    if (!options.lightWeights.empty() && options.lightWeights.size() != g.size()) {
        return makeError(ErrorCode::InvalidArgument,
                         fmt::format("channel fit: {} light weights for {} lights",
                                     options.lightWeights.size(), g.size()));
    }
    DenseMatrix gtg(kBands, kBands);
    for (std::size_t j = 0; j < g.size(); ++j) {
        const double weight = options.lightWeights.empty() ? 1.0 : options.lightWeights[j];
        const DenseMatrix gj = g[j].transposed() * g[j];
        for (std::size_t a = 0; a < kBands; ++a) {
            for (std::size_t b = 0; b < kBands; ++b) {
                gtg(a, b) += weight * gj(a, b);
            }
        }
    }
    const SymmetricEigen eig = symmetricEigen(l->transposed() * gtg * *l);
    DenseMatrix q(kBands, kChannels);
    for (std::size_t r = 0; r < kBands; ++r) {
        for (std::size_t k = 0; k < kChannels; ++k) {
            q(r, k) = eig.vectors(r, k);
        }
    }
    const DenseMatrix p = linvT * q; // columns are the projection vectors
    const DenseMatrix w = *l * q;    // columns are the reconstruction spectra
    for (std::size_t k = 0; k < kChannels; ++k) {
        // Sign: the reconstruction spectrum should be mostly positive, for readable files.
        double sum = 0.0;
        for (std::size_t r = 0; r < kBands; ++r) {
            sum += w(r, k);
        }
        const double sign = sum < 0.0 ? -1.0 : 1.0;
        for (std::size_t r = 0; r < kBands; ++r) {
            basis.project[k][r] = sign * p(r, k);
            basis.reconstruct[k][r] = sign * w(r, k);
        }
    }
    return basis;
}

} // namespace replica::pipeline::spectral
