// Light-adaptive channel encoding (representation "adaptive_k6"): a K = 6 basis rebuilt whenever
// the light changes, whose first three coefficients span exactly that light's XYZ functionals (so
// the light present is rendered exactly, any reflectance) and whose other three are the best
// complement for the other training lights (so the previous light, and a light not yet re-encoded
// for, degrade gracefully). Per pixel it costs what every K = 6 representation costs; per light
// change the CPU rebuilds the basis (about a millisecond) and re-encodes each surface from its
// 36-band reflectance kept on the CPU (36 x 6 multiply-adds per texel). See docs/accuracy.md.
//
// How the appliance uses it (render/booth_scene_pass.h, basis "adaptive_k6", the default):
//   at start:      encoder = AdaptiveEncoder::createDefault(dataDir()); the surface is uploaded in
//                  encoder.generalBasis().
//   light changes: (a newly classified lamp, or in direct-sensor mode a sensed shape moved by more
//                  than kAdaptiveReencodeDistance) basisFor(light), the scene's palette projected
//                  onto it (texels follow by linearity) and the textures replaced, synchronously
//                  in the draw that first sees the light (a few ms), so that the swap frame is a
//                  function of the recorded inputs. Surfaces without a palette would keep a
//                  ReflectanceImage and call encodeSurface()/encodeTexels() instead.
//   every frame:   M = colour::channelToXyz(basis, observer, light): [I3 | 0] for the light
//                  encoded for, graceful for any other.
#pragma once

#include <cstddef>
#include <filesystem>
#include <vector>

#include <pipeline/base/expected.h>
#include <pipeline/colour/channel_basis.h>
#include <pipeline/spectral/dense_matrix.h>
#include <pipeline/spectral/reference_sets.h>
#include <pipeline/spectral/representation.h>

namespace replica::pipeline::spectral {

struct AdaptiveEncoderOptions {
    // Tikhonov term on the reflectance prior, relative to its mean diagonal (as BasisFitOptions).
    double ridge = 1e-4;
    // Weight of each training light in the complement's objective (empty: all 1).
    std::vector<double> lightWeights;
    // A direction of the light's XYZ functionals whose prior variance is below this fraction of
    // the largest counts as absent (a single- or two-band light has one or two, not three); the
    // freed coefficients go to the complement. Larger values drop real, weak directions (1e-9
    // leaves a 1e-5 XYZ error under a 30 nm wide line light), smaller ones keep rounding noise.
    double rankTolerance = 1e-12;
};

class AdaptiveEncoder
{
public:
    // The prior (second moment of 'reflectances', CIELAB-weighted as the fits are) and the lights
    // whose colour errors the three free functions minimise (CIELAB-like metric, fit_metric.h).
    static Expected<AdaptiveEncoder> create(const Observer& obs,
                                            const Spectrum& d65,
                                            const NamedSpectra& reflectances,
                                            const NamedSpectra& lights,
                                            const AdaptiveEncoderOptions& options = {});
    // The shipped choice: CES01-99, the eight lights weighted as replica_k6 is
    // (options.lightWeights is replaced by those weights).
    static Expected<AdaptiveEncoder> createDefault(const std::filesystem::path& dataDir,
                                                   AdaptiveEncoderOptions options = {});

    // The basis for 'light' (any scale). With r the rank of the light's XYZ functionals (3 unless
    // it is nearly monochromatic), project[0..r) span them (r = 3: they are the functionals
    // themselves, so a texel's first three coefficients are its XYZ under the light at Y = 1), and
    // reconstruct is the prior's least-squares estimate given all six, W = C P^T (P C P^T)^-1, so
    // that channelToXyz(basis, light) reproduces the light's XYZ of every reflectance exactly.
    // Fails for a band that is not finite and for a light without luminance (Y <= 0).
    Expected<colour::ChannelBasis> basisFor(const Spectrum& light) const;
    // The basis before any light is known: the best light-aware basis for the training lights (it
    // spans what fitChannelBasis finds with the same data).
    const colour::ChannelBasis& generalBasis() const { return general_; }
    const Observer& observer() const { return obs_; }

private:
    AdaptiveEncoder() = default;
    // Rows 'fixed' (r x 36, may be empty) completed by the best 6 - r rows; an error when
    // the prior cannot be conditioned.
    Expected<colour::ChannelBasis> complete(const DenseMatrix& fixed) const;

    Observer obs_;
    DenseMatrix c_;   // 36 x 36 reflectance prior, ridge included
    DenseMatrix gtg_; // 36 x 36, sum over lights of w_j (H_j A_j)^T (H_j A_j)
    double rankTolerance_ = 1e-12;
    colour::ChannelBasis general_;
};

// c[k] = sum_l project[k](l) bands[l] for 'count' texels: 'bands' holds kBands floats per texel,
// 'coeffs' receives kChannels floats per texel (the layout of render::SurfaceImage). Float, as the
// textures are; about 1e-7 relative rounding.
void encodeTexels(const colour::ChannelBasis& basis,
                  const float* bands,
                  std::size_t count,
                  float* coeffs);

// A surface's diffuse reflectance kept on the CPU: kBands floats per texel, rows from the bottom
// up (GL texture order, as render::SurfaceImage).
struct ReflectanceImage {
    int width = 0;
    int height = 0;
    std::vector<float> bands;
};

// A surface encoded for one light: the basis, the six XYZ vectors under that light
// (channelToXyz(basis, observer, light), what the renderer uploads as its 6 x 3 matrix) and
// kChannels coefficients per texel (planes 1-3 and 4-6 are the paper's two RGB float images).
struct AdaptiveSurface {
    colour::ChannelBasis basis;
    colour::ChannelToXyz toXyz{};
    int width = 0;
    int height = 0;
    std::vector<float> coeffs;
};

// basisFor(light), then encodeTexels over the whole image. Fails as basisFor does, and for an
// image whose size does not match its data.
Expected<AdaptiveSurface>
encodeSurface(const AdaptiveEncoder& encoder, const ReflectanceImage& image, const Spectrum& light);

// Direct-sensor mode with a light-adaptive encoder: the surface is re-encoded when the sensed
// spectrum's shape (spectralShapeDistance) has moved more than this from the one it was last
// encoded for. The error of the stale encoding grows linearly with the drift: at 0.01, surfaces
// encoded for the old shape and shown under the new one stay within 0.012 mean / 0.042 max dE00
// on the ColorChecker (worst over the eight lights moved towards each other and by band
// noise; docs/accuracy.md), a quarter of the mean goal and a seventh of its max goal,
// leaving the rest to the spectrometer. It is 7 times the noise floor at data-sheet noise (p99.9
// distance 0.0014), so sensor noise alone does not re-encode.
constexpr double kAdaptiveReencodeDistance = 0.01;

// For choosing when a drifting sensed light needs a re-encode: the light (1 - a) from + a towards
// (each scaled to Y = 1) whose spectralShapeDistance from 'from' is 'distance', a found by
// bisection. Fails for a light without luminance, a distance <= 0, and when even 'towards'
// itself is closer to 'from' than 'distance'.
Expected<Spectrum>
shiftedLight(const Observer& obs, const Spectrum& from, const Spectrum& towards, double distance);

// Representation "adaptive_k6": encode()/lightVectors() use the general basis; adaptedTo(light)
// gives the fixed basis representation encoded for that light.
std::unique_ptr<Representation> makeAdaptiveRepresentation(AdaptiveEncoder encoder);

} // namespace replica::pipeline::spectral
