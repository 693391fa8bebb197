// 'replica spectral fit': derive the channel data the appliance ships (replica_k6's basis and
// light weights, the paper's six-channel model) from training reflectances and lights.
#pragma once

#include <string>

#include <pipeline/spectral/light_weights.h>

namespace replica::platform {

// The options of the fit subcommand (registered with the others in spectral_command.cpp).
struct SpectralFitOptions {
    std::string reflectances = "ces99";
    std::string lights;
    // Weights of named lights in replica_k6 (others 1), spectral::defaultLightWeights().
    std::string weights = pipeline::spectral::defaultLightWeightsText();
    std::string out;
    int rounds = 1000;
};

// Runs the fit and writes its files; the exit code (kExitOk, or a failure after a message).
int runSpectralFit(const SpectralFitOptions& o);

} // namespace replica::platform
