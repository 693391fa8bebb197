// Representation names to objects, loading the fitted channel data the appliance ships.
#include <fmt/format.h>

#include <pipeline/spectral/adaptive_encoding.h>
#include <pipeline/spectral/representation_catalogue.h>
#include <pipeline/spectral/six_channel_model.h>

namespace replica::pipeline::spectral {

std::vector<std::string> representationNames()
{
    return {"rgb3",       "paper6",     "replica_k6", "adaptive_k6",
            "spectral36", "general_k6", "pca6",       "box6"};
}

std::vector<std::string> channelBasisNames()
{
    return {"adaptive_k6", "replica_k6", "general_k6", "pca6", "box6"};
}

Expected<std::unique_ptr<Representation>> makeRepresentation(const std::filesystem::path& dataDir,
                                                             const Observer& obs,
                                                             const Spectrum& d65,
                                                             const std::string& name)
{
    const auto channels = dataDir / "channels";
    if (name == "rgb3") {
        return makeNaiveRgb(obs, d65);
    }
    if (name == "spectral36") {
        return makeFullSpectral(obs);
    }
    if (name == "box6") {
        return makeBasisRepresentation(obs, colour::boxBasis());
    }
    if (name == "adaptive_k6") {
        auto encoder = AdaptiveEncoder::createDefault(dataDir);
        if (!encoder) {
            return tl::unexpected(encoder.error());
        }
        return makeAdaptiveRepresentation(std::move(*encoder));
    }
    if (name == "paper6") {
        auto model = loadSixChannelModel(channels / "paper6.csv");
        if (!model) {
            return tl::unexpected(model.error());
        }
        return makeSixChannelRepresentation(obs, std::move(*model));
    }
    if (name == "replica_k6" || name == "general_k6" || name == "pca6") {
        auto basis = colour::loadChannelBasis(channels / (name + ".csv"));
        if (!basis) {
            return tl::unexpected(basis.error());
        }
        return makeBasisRepresentation(obs, std::move(*basis));
    }
    return makeError(ErrorCode::InvalidArgument,
                     fmt::format("no representation named '{}' (known: {})", name,
                                 fmt::join(representationNames(), ", ")));
}

} // namespace replica::pipeline::spectral
