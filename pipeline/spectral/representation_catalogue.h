// The representations by name, as the CLI and the accuracy table use them, with the shipped channel
// data from data/channels/.
#pragma once

#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include <pipeline/base/expected.h>
#include <pipeline/spectral/representation.h>

namespace replica::pipeline::spectral {

// "rgb3" (1), "paper6" (2), "replica_k6" (3 with one basis fitted for all lights, shipped in
// data/channels/), "adaptive_k6" (3 re-encoded for each light, adaptive_encoding.h; the
// appliance's default), "spectral36" (4), and for comparison "general_k6" (light-aware, all
// training lights equal), "pca6" (principal components, light-independent) and "box6" (six box
// bands).
std::vector<std::string> representationNames();
// The K = 6 channel bases among them: what the GL renderer's two RGB coefficient textures hold, so
// what 'replica run' and 'replica render' accept (adaptive_k6 first: the default).
std::vector<std::string> channelBasisNames();
// The fixed basis 'replica spectral fit' derives and ships (data/channels/replica_k6.csv).
constexpr const char* kDefaultRepresentation = "replica_k6";
// What the appliance renders with and 'replica spectral eval' reports unless told otherwise.
constexpr const char* kApplianceRepresentation = "adaptive_k6";

Expected<std::unique_ptr<Representation>> makeRepresentation(const std::filesystem::path& dataDir,
                                                             const Observer& obs,
                                                             const Spectrum& d65,
                                                             const std::string& name);

} // namespace replica::pipeline::spectral
