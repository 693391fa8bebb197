// The full-spectral, naive-RGB and channel-basis representations.
#include <pipeline/colour/matrix3.h>
#include <pipeline/spectral/representation.h>

namespace replica::pipeline::spectral {
namespace {

using colour::kBands;

class FullSpectral final : public Representation
{
public:
    explicit FullSpectral(const Observer& obs) : obs_(obs) {}
    std::string name() const override { return "spectral36"; }
    std::size_t channels() const override { return kBands; }
    std::vector<double> encode(const Spectrum& reflectance) const override
    {
        return {reflectance.v.begin(), reflectance.v.end()};
    }
    std::vector<Xyz> lightVectors(const Spectrum& light) const override
    {
        std::vector<Xyz> m(kBands, Xyz{0.0});
        const double y = colour::spectrumToXyz(obs_, light).y;
        if (!(y > 0.0)) {
            return m;
        }
        const double k = colour::kStepNm / y;
        for (std::size_t i = 0; i < kBands; ++i) {
            m[i] = Xyz{obs_.xbar[i], obs_.ybar[i], obs_.zbar[i]} * (light[i] * k);
        }
        return m;
    }

private:
    Observer obs_;
};

// IEC 61966-2-1 (sRGB) primaries and D65 white: linear RGB to XYZ.
constexpr colour::Matrix3 kSrgbToXyz{
        {{0.4124, 0.3576, 0.1805}, {0.2126, 0.7152, 0.0722}, {0.0193, 0.1192, 0.9505}}};

class NaiveRgb final : public Representation
{
public:
    NaiveRgb(const Observer& obs, const Spectrum& d65) : obs_(obs), d65_(d65)
    {
        xyzToRgb_ = colour::inverse(kSrgbToXyz);
        const Xyz w = colour::spectrumToXyz(obs_, d65_);
        white_ = colour::applyMatrix(xyzToRgb_, w * (1.0 / w.y));
    }
    std::string name() const override { return "rgb3"; }
    std::size_t channels() const override { return 3; }
    std::vector<double> encode(const Spectrum& reflectance) const override
    {
        const Xyz xyz = colour::reflectanceToXyz(obs_, d65_, reflectance) * 0.01;
        const Xyz rgb = colour::applyMatrix(xyzToRgb_, xyz);
        return {rgb.x / white_.x, rgb.y / white_.y, rgb.z / white_.z};
    }
    std::vector<Xyz> lightVectors(const Spectrum& light) const override
    {
        std::vector<Xyz> m(3, Xyz{0.0});
        const Xyz xyz = colour::spectrumToXyz(obs_, light);
        if (!(xyz.y > 0.0)) {
            return m;
        }
        const Xyz rgb = colour::applyMatrix(xyzToRgb_, xyz * (1.0 / xyz.y));
        const double l[3] = {rgb.x, rgb.y, rgb.z};
        for (std::size_t k = 0; k < 3; ++k) {
            m[k] = Xyz{kSrgbToXyz[0][k], kSrgbToXyz[1][k], kSrgbToXyz[2][k]} * l[k];
        }
        return m;
    }

private:
    Observer obs_;
    Spectrum d65_;
    colour::Matrix3 xyzToRgb_{};
    Xyz white_{1.0};
};

class BasisRepresentation final : public Representation
{
public:
    BasisRepresentation(const Observer& obs, colour::ChannelBasis basis)
        : obs_(obs), basis_(std::move(basis))
    {}
    std::string name() const override { return basis_.name; }
    std::size_t channels() const override { return colour::kChannels; }
    std::vector<double> encode(const Spectrum& reflectance) const override
    {
        const auto c = colour::projectReflectance(basis_, reflectance);
        return {c.begin(), c.end()};
    }
    std::vector<Xyz> lightVectors(const Spectrum& light) const override
    {
        const auto m = colour::channelToXyz(basis_, obs_, light);
        return {m.begin(), m.end()};
    }

private:
    Observer obs_;
    colour::ChannelBasis basis_;
};

} // namespace

Xyz shade(const std::vector<double>& texel, const std::vector<Xyz>& m)
{
    Xyz out{0.0};
    const std::size_t n = std::min(texel.size(), m.size());
    for (std::size_t k = 0; k < n; ++k) {
        out += m[k] * texel[k];
    }
    return out;
}

std::unique_ptr<Representation> makeFullSpectral(const Observer& obs)
{
    return std::make_unique<FullSpectral>(obs);
}

std::unique_ptr<Representation> makeNaiveRgb(const Observer& obs, const Spectrum& d65)
{
    return std::make_unique<NaiveRgb>(obs, d65);
}

std::unique_ptr<Representation> makeBasisRepresentation(const Observer& obs,
                                                        colour::ChannelBasis basis)
{
    return std::make_unique<BasisRepresentation>(obs, std::move(basis));
}

} // namespace replica::pipeline::spectral
