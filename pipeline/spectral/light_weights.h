// The training lights' weights of the shipped replica_k6 basis: what the offline basis fit
// (offline/spectral/basis_fit.h) uses by default and what the run's light-adaptive encoding
// (adaptive_encoding.h) completes its basis with, so that both weigh the lights alike.
#pragma once

#include <string>
#include <utility>
#include <vector>

namespace replica::pipeline::spectral {

// The booth's lamps (A for tungsten, F8 the D50 fluorescent simulator, F7 the D65 simulator)
// first, daylight next; a training light not named weighs 1 (docs/accuracy.md).
std::vector<std::pair<std::string, double>> defaultLightWeights();
// The same as 'replica spectral fit --weights' spells them: "A=30,F8=60,...".
std::string defaultLightWeightsText();

} // namespace replica::pipeline::spectral
