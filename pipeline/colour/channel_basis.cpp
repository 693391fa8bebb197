// Channel bases and the per-light channel-to-XYZ matrix.
#include <algorithm>

#include <pipeline/colour/channel_basis.h>

namespace replica::pipeline::colour {

ChannelBasis boxBasis()
{
    ChannelBasis b;
    b.name = "box6";
    constexpr std::size_t kPerBand =
            6; // 6 working bands per box; the last box gets the remaining 6
    for (std::size_t i = 0; i < kBands; ++i) {
        const std::size_t k = std::min(i / kPerBand, kChannels - 1);
        b.reconstruct[k][i] = 1.0;
    }
    for (std::size_t k = 0; k < kChannels; ++k) {
        const double n = b.reconstruct[k].sum();
        b.project[k] = b.reconstruct[k] * (1.0 / n);
    }
    return b;
}

ChannelCoeffs projectReflectance(const ChannelBasis& basis, const Spectrum& reflectance)
{
    ChannelCoeffs c{};
    for (std::size_t k = 0; k < kChannels; ++k) {
        c[k] = (basis.project[k] * reflectance).sum();
    }
    return c;
}

ChannelToXyz channelToXyz(const ChannelBasis& basis, const Observer& obs, const Spectrum& light)
{
    ChannelToXyz m{};
    const double lightY = spectrumToXyz(obs, light).y;
    if (!(lightY > 0.0)) {
        return m;
    }
    const Spectrum unitLight = light * (1.0 / lightY);
    for (std::size_t k = 0; k < kChannels; ++k) {
        m[k] = spectrumToXyz(obs, unitLight * basis.reconstruct[k]);
    }
    return m;
}

} // namespace replica::pipeline::colour
