// The light-adaptive K = 6 encoding: a basis exact for the light present, completed by the best
// general functions, and the per-texel re-encoding.
#include <algorithm>
#include <array>
#include <cmath>

#include <fmt/format.h>

#include <pipeline/spectral/adaptive_encoding.h>
#include <pipeline/spectral/fit_metric.h>
#include <pipeline/spectral/light_classifier.h>
#include <pipeline/spectral/light_weights.h>

namespace replica::pipeline::spectral {
namespace {

using colour::kBands;
using colour::kChannels;

DenseMatrix symmetrised(const DenseMatrix& a)
{
    DenseMatrix s(a.rows(), a.cols());
    for (std::size_t i = 0; i < a.rows(); ++i) {
        for (std::size_t j = 0; j < a.cols(); ++j) {
            s(i, j) = 0.5 * (a(i, j) + a(j, i));
        }
    }
    return s;
}

// The light's XYZ functionals at Y = 1 (3 x 36), as channelToXyz applies them.
DenseMatrix xyzFunctionals(const Observer& obs, const Spectrum& unitLight)
{
    DenseMatrix a(3, kBands);
    for (std::size_t l = 0; l < kBands; ++l) {
        a(0, l) = obs.xbar[l] * unitLight[l] * colour::kStepNm;
        a(1, l) = obs.ybar[l] * unitLight[l] * colour::kStepNm;
        a(2, l) = obs.zbar[l] * unitLight[l] * colour::kStepNm;
    }
    return a;
}

} // namespace

Expected<AdaptiveEncoder> AdaptiveEncoder::create(const Observer& obs,
                                                  const Spectrum& d65,
                                                  const NamedSpectra& reflectances,
                                                  const NamedSpectra& lights,
                                                  const AdaptiveEncoderOptions& options)
{
    if (reflectances.size() < kChannels) {
        return makeError(ErrorCode::InvalidArgument,
                         fmt::format("adaptive encoder: needs at least {} training reflectances, "
                                     "got {}",
                                     kChannels, reflectances.size()));
    }
    if (!options.lightWeights.empty() && options.lightWeights.size() != lights.size()) {
        return makeError(ErrorCode::InvalidArgument,
                         fmt::format("adaptive encoder: {} light weights for {} lights",
                                     options.lightWeights.size(), lights.size()));
    }
    if (!(options.ridge > 0.0) || !(options.rankTolerance > 0.0) ||
        !(options.rankTolerance < 1.0)) {
        return makeError(ErrorCode::InvalidArgument,
                         "adaptive encoder: need ridge > 0 and 0 < rankTolerance < 1");
    }
    const auto fitLights = makeFitLights(obs, d65, lights, true);
    if (fitLights.empty() || fitLights.size() != lights.size()) {
        return makeError(ErrorCode::InvalidArgument,
                         "adaptive encoder: every training light needs luminance (Y > 0)");
    }
    AdaptiveEncoder e;
    e.obs_ = obs;
    e.rankTolerance_ = options.rankTolerance;
    e.c_ = weightedSecondMoment(reflectances, sampleWeights(obs, reflectances, true));
    double trace = 0.0;
    for (std::size_t i = 0; i < kBands; ++i) {
        trace += e.c_(i, i);
    }
    if (!(trace > 0.0)) {
        return makeError(ErrorCode::InvalidArgument,
                         "adaptive encoder: the training reflectances are all zero");
    }
    for (std::size_t i = 0; i < kBands; ++i) {
        e.c_(i, i) += options.ridge * trace / static_cast<double>(kBands);
    }
    e.gtg_ = DenseMatrix(kBands, kBands);
    for (std::size_t j = 0; j < fitLights.size(); ++j) {
        const double w = options.lightWeights.empty() ? 1.0 : options.lightWeights[j];
        const DenseMatrix g = fitLights[j].h * fitLights[j].a;
        const DenseMatrix gg = g.transposed() * g;
        for (std::size_t a = 0; a < kBands; ++a) {
            for (std::size_t b = 0; b < kBands; ++b) {
                e.gtg_(a, b) += w * gg(a, b);
            }
        }
    }
    auto general = e.complete(DenseMatrix(0, kBands));
    if (!general) {
        return tl::unexpected(general.error());
    }
    e.general_ = std::move(*general);
    e.general_.name = "adaptive_k6";
    return e;
}

Expected<AdaptiveEncoder> AdaptiveEncoder::createDefault(const std::filesystem::path& dataDir,
                                                         AdaptiveEncoderOptions options)
{
    auto obs = colour::loadCie1931(dataDir);
    if (!obs) {
        return tl::unexpected(obs.error());
    }
    auto d65 = loadCieIlluminant(dataDir, "D65");
    if (!d65) {
        return tl::unexpected(d65.error());
    }
    auto training = loadReflectanceSet(dataDir, "ces99");
    if (!training) {
        return tl::unexpected(training.error());
    }
    NamedSpectra lights;
    options.lightWeights.clear();
    const auto weights = defaultLightWeights();
    for (const auto& name : evaluationLightNames()) {
        auto l = loadCieIlluminant(dataDir, name);
        if (!l) {
            return tl::unexpected(l.error());
        }
        lights.names.push_back(name);
        lights.spectra.push_back(*l);
        double w = 1.0;
        for (const auto& [n, v] : weights) {
            w = n == name ? v : w;
        }
        options.lightWeights.push_back(w);
    }
    return create(*obs, *d65, *training, lights, options);
}

Expected<colour::ChannelBasis> AdaptiveEncoder::basisFor(const Spectrum& light) const
{
    for (std::size_t l = 0; l < kBands; ++l) {
        if (!std::isfinite(light[l])) {
            return makeError(ErrorCode::InvalidArgument,
                             fmt::format("adaptive encoding: the light's band at {} nm is not a "
                                         "finite number",
                                         colour::bandCentreNm(l)));
        }
    }
    const double y = colour::spectrumToXyz(obs_, light).y;
    if (!(y > 0.0) || !std::isfinite(y)) {
        return makeError(ErrorCode::InvalidArgument,
                         "adaptive encoding: the light has no luminance (Y <= 0); a dark or "
                         "all-zero spectrum cannot be encoded for, keep the previous encoding");
    }
    const DenseMatrix a = xyzFunctionals(obs_, light * (1.0 / y));
    // Independent directions of the light's functionals, measured in the prior's metric: a
    // narrow-band light gives fewer than three, and a dependent row would make P C P^T singular.
    const DenseMatrix s = symmetrised(a * c_ * a.transposed());
    const SymmetricEigen eig = symmetricEigen(s);
    std::size_t rank = 0;
    for (double v : eig.values) {
        rank += v > rankTolerance_ * eig.values[0] ? 1 : 0;
    }
    DenseMatrix fixed(rank, kBands);
    if (rank == 3) {
        fixed = a; // the coefficients are then the texel's XYZ under the light
    } else {
        for (std::size_t i = 0; i < rank; ++i) {
            const double scale = 1.0 / std::sqrt(eig.values[i]);
            for (std::size_t l = 0; l < kBands; ++l) {
                double v = 0.0;
                for (std::size_t r = 0; r < 3; ++r) {
                    v += eig.vectors(r, i) * a(r, l);
                }
                fixed(i, l) = v * scale;
            }
        }
    }
    auto basis = complete(fixed);
    if (!basis) {
        return tl::unexpected(basis.error());
    }
    basis->name = "adaptive_k6";
    return basis;
}

Expected<colour::ChannelBasis> AdaptiveEncoder::complete(const DenseMatrix& fixed) const
{
    const std::size_t r = fixed.rows();
    // The prior conditioned on the fixed functionals: C' = C - C R^T (R C R^T)^-1 R C. What the
    // free functions can still add is the part of each training light's colour that C' leaves.
    DenseMatrix cc = c_;
    if (r > 0) {
        const DenseMatrix k = c_ * fixed.transposed(); // 36 x r
        auto x = solve(fixed * k, k.transposed());     // (R C R^T)^-1 R C, r x 36
        if (!x) {
            return makeError(ErrorCode::InvalidArgument,
                             "adaptive encoding: the light's functionals are degenerate (" +
                                     x.error().message + ")");
        }
        const DenseMatrix kx = k * *x;
        for (std::size_t i = 0; i < kBands; ++i) {
            for (std::size_t j = 0; j < kBands; ++j) {
                cc(i, j) -= kx(i, j);
            }
        }
        cc = symmetrised(cc);
    }
    // C' = V diag(mu) V^T on its range; with u = diag(sqrt mu) V^T q the best free rows are the top
    // eigenvectors of diag(sqrt mu) V^T G^T G V diag(sqrt mu), mapped back by q = V diag(1/sqrt mu)
    // u (the generalised eigenproblem (C' G^T G C', C') of basis_fit.h, on what R leaves).
    // C' has rank exactly 36 - r (C is positive definite, the fixed rows independent): its range
    // is its top 36 - r eigenvectors, each with at least the ridge's share of variance.
    const SymmetricEigen ce = symmetricEigen(cc);
    const std::size_t m = kBands - r;
    const std::size_t free = kChannels - r;
    if (!(ce.values[m - 1] > 0.0)) {
        return makeError(ErrorCode::InvalidArgument,
                         "adaptive encoding: the reflectance prior has too few directions left");
    }
    DenseMatrix half(kBands, m); // V diag(sqrt mu)
    DenseMatrix invHalf(kBands, m);
    for (std::size_t j = 0; j < m; ++j) {
        const double mu = ce.values[j];
        for (std::size_t l = 0; l < kBands; ++l) {
            half(l, j) = ce.vectors(l, j) * std::sqrt(mu);
            invHalf(l, j) = ce.vectors(l, j) / std::sqrt(mu);
        }
    }
    const SymmetricEigen ge = symmetricEigen(symmetrised(half.transposed() * gtg_ * half));
    DenseMatrix p(kChannels, kBands);
    for (std::size_t i = 0; i < r; ++i) {
        for (std::size_t l = 0; l < kBands; ++l) {
            p(i, l) = fixed(i, l);
        }
    }
    for (std::size_t k = 0; k < free; ++k) {
        for (std::size_t l = 0; l < kBands; ++l) {
            double v = 0.0;
            for (std::size_t j = 0; j < m; ++j) {
                v += invHalf(l, j) * ge.vectors(j, k);
            }
            p(r + k, l) = v;
        }
    }
    // W = C P^T (P C P^T)^-1: the prior's estimate of a reflectance from its six coefficients, so
    // P W = I and every functional in the span of P (the light's XYZ among them) is reproduced.
    const DenseMatrix cpt = c_ * p.transposed(); // 36 x 6
    auto wt = solve(p * cpt, cpt.transposed());  // (P C P^T)^-1 P C = W^T, 6 x 36
    if (!wt) {
        return makeError(ErrorCode::InvalidArgument,
                         "adaptive encoding: the six functions are degenerate (" +
                                 wt.error().message + ")");
    }
    colour::ChannelBasis basis;
    for (std::size_t k = 0; k < kChannels; ++k) {
        // The free functions' sign is arbitrary: make their reconstruction mostly positive.
        double sum = 0.0;
        for (std::size_t l = 0; l < kBands; ++l) {
            sum += (*wt)(k, l);
        }
        const double sign = k >= r && sum < 0.0 ? -1.0 : 1.0;
        for (std::size_t l = 0; l < kBands; ++l) {
            basis.project[k][l] = sign * p(k, l);
            basis.reconstruct[k][l] = sign * (*wt)(k, l);
        }
    }
    return basis;
}

void encodeTexels(const colour::ChannelBasis& basis,
                  const float* bands,
                  std::size_t count,
                  float* coeffs)
{
    // The projection transposed and padded to eight lanes, so that each band is one broadcast
    // multiply-add across all six coefficients (vectorises without reassociating any sum).
    constexpr std::size_t kLanes = 8;
    alignas(32) std::array<std::array<float, kLanes>, kBands> pt{};
    for (std::size_t l = 0; l < kBands; ++l) {
        for (std::size_t k = 0; k < kChannels; ++k) {
            pt[l][k] = static_cast<float>(basis.project[k][l]);
        }
    }
    for (std::size_t t = 0; t < count; ++t) {
        const float* in = bands + t * kBands;
        alignas(32) std::array<float, kLanes> acc{};
        for (std::size_t l = 0; l < kBands; ++l) {
            const float x = in[l];
            for (std::size_t k = 0; k < kLanes; ++k) {
                acc[k] += pt[l][k] * x;
            }
        }
        float* out = coeffs + t * kChannels;
        for (std::size_t k = 0; k < kChannels; ++k) {
            out[k] = acc[k];
        }
    }
}

Expected<AdaptiveSurface>
encodeSurface(const AdaptiveEncoder& encoder, const ReflectanceImage& image, const Spectrum& light)
{
    if (image.width < 0 || image.height < 0 ||
        image.bands.size() != static_cast<std::size_t>(image.width) *
                                      static_cast<std::size_t>(image.height) * kBands) {
        return makeError(ErrorCode::InvalidArgument,
                         fmt::format("adaptive encoding: a {} x {} reflectance image needs {} "
                                     "floats ({} bands per texel), it has {}",
                                     image.width, image.height,
                                     static_cast<long long>(image.width) * image.height *
                                             static_cast<long long>(kBands),
                                     kBands, image.bands.size()));
    }
    auto basis = encoder.basisFor(light);
    if (!basis) {
        return tl::unexpected(basis.error());
    }
    AdaptiveSurface s;
    s.basis = std::move(*basis);
    s.toXyz = colour::channelToXyz(s.basis, encoder.observer(), light);
    s.width = image.width;
    s.height = image.height;
    const std::size_t texels = image.bands.size() / kBands;
    s.coeffs.resize(texels * kChannels);
    encodeTexels(s.basis, image.bands.data(), texels, s.coeffs.data());
    return s;
}

namespace {

class AdaptiveRepresentation final : public Representation
{
public:
    explicit AdaptiveRepresentation(AdaptiveEncoder encoder)
        : encoder_(std::move(encoder)),
          general_(makeBasisRepresentation(encoder_.observer(), encoder_.generalBasis()))
    {}
    std::string name() const override { return "adaptive_k6"; }
    std::size_t channels() const override { return kChannels; }
    std::vector<double> encode(const Spectrum& reflectance) const override
    {
        return general_->encode(reflectance);
    }
    std::vector<Xyz> lightVectors(const Spectrum& light) const override
    {
        return general_->lightVectors(light);
    }
    Expected<std::unique_ptr<Representation>> adaptedTo(const Spectrum& light) const override
    {
        auto basis = encoder_.basisFor(light);
        if (!basis) {
            return tl::unexpected(basis.error());
        }
        return makeBasisRepresentation(encoder_.observer(), std::move(*basis));
    }

private:
    AdaptiveEncoder encoder_;
    std::unique_ptr<Representation> general_;
};

} // namespace

Expected<Spectrum>
shiftedLight(const Observer& obs, const Spectrum& from, const Spectrum& towards, double distance)
{
    const double yFrom = colour::spectrumToXyz(obs, from).y;
    const double yTowards = colour::spectrumToXyz(obs, towards).y;
    if (!(yFrom > 0.0) || !(yTowards > 0.0) || !(distance > 0.0)) {
        return makeError(ErrorCode::InvalidArgument,
                         "shifted light: both lights need luminance and the distance must be > 0");
    }
    const Spectrum a = from * (1.0 / yFrom);
    const Spectrum b = towards * (1.0 / yTowards);
    const auto mix = [&](double t) { return a * (1.0 - t) + b * t; };
    if (!(spectralShapeDistance(a, b) >= distance)) {
        return makeError(ErrorCode::InvalidArgument,
                         fmt::format("shifted light: the two lights are only {:.4f} apart in shape",
                                     spectralShapeDistance(a, b)));
    }
    // The distance grows from 0 at t = 0; take the smallest t that reaches it (bisection on the
    // first crossing is enough for mixtures, whose distance rises monotonically in practice).
    double lo = 0.0;
    double hi = 1.0;
    for (int i = 0; i < 60; ++i) {
        const double mid = 0.5 * (lo + hi);
        (spectralShapeDistance(a, mix(mid)) < distance ? lo : hi) = mid;
    }
    return mix(hi);
}

std::unique_ptr<Representation> makeAdaptiveRepresentation(AdaptiveEncoder encoder)
{
    return std::make_unique<AdaptiveRepresentation>(std::move(encoder));
}

} // namespace replica::pipeline::spectral
