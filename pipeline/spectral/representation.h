// Colour representations compared in docs/accuracy.md. Each is linear in two parts: per-texel data
// t (computed once per surface) and per-light vectors m_k (recomputed on the CPU when the light
// changes), and a texel's colour is XYZ = sum_k t_k m_k. With the light scaled to Y = 1, a perfect
// white texel has Y = 1; the renderer multiplies by E / pi for cd/m^2.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include <pipeline/base/expected.h>
#include <pipeline/colour/channel_basis.h>
#include <pipeline/colour/spectrum.h>
#include <pipeline/colour/xyz.h>

namespace replica::pipeline::spectral {

using colour::Observer;
using colour::Spectrum;
using colour::Xyz;

class Representation
{
public:
    virtual ~Representation() = default;
    virtual std::string name() const = 0;
    // Number of per-texel values (3, 6 or 36).
    virtual std::size_t channels() const = 0;
    // Per-texel data of a reflectance (0..1 per band).
    virtual std::vector<double> encode(const Spectrum& reflectance) const = 0;
    // Per-light vectors, channels() of them, for a light of any scale (normalised to Y = 1 inside).
    // A light with Y <= 0 gives zero vectors.
    virtual std::vector<Xyz> lightVectors(const Spectrum& light) const = 0;
    // A representation whose texel data depend on the light (adaptive_k6) re-encodes every surface
    // when the light changes: this is the fixed representation it becomes once encoded for
    // 'light'. Null for the others, whose texel data never change. Fails for a light an adaptive
    // representation cannot encode for (no luminance, bands not finite).
    virtual Expected<std::unique_ptr<Representation>> adaptedTo(const Spectrum& light) const
    {
        (void)light;
        return std::unique_ptr<Representation>{};
    }
};

// XYZ = sum_k texel[k] * m[k]: the per-pixel work of every representation.
Xyz shade(const std::vector<double>& texel, const std::vector<Xyz>& m);

// (4) The reference: 36 reflectance bands per texel, m_l = light(l) cmf(l) 10 nm / Y(light).
std::unique_ptr<Representation> makeFullSpectral(const Observer& obs);

// (1) Naive RGB: the reflectance as its linear sRGB under D65 (balanced so that the perfect white
// is (1, 1, 1)), the light as its linear sRGB, multiplied channel by channel. Exact under D65 only.
std::unique_ptr<Representation> makeNaiveRgb(const Observer& obs, const Spectrum& d65);

// (3) A channel basis (colour/channel_basis.h): texel = projection coefficients, m_k = XYZ of the
// k-th reconstruction spectrum under the light. Exact for reflectances in the basis' span, whatever
// the light.
std::unique_ptr<Representation> makeBasisRepresentation(const Observer& obs,
                                                        colour::ChannelBasis basis);

} // namespace replica::pipeline::spectral
