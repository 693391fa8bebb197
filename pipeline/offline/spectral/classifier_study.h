// Measuring the light classifier on noisy simulated spectra: confusion, flicker and the smallest
// spectral difference it still tells apart (figures for docs/accuracy.md and the tests).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <pipeline/offline/spectral/band_noise.h>
#include <pipeline/spectral/light_classifier.h>

namespace replica::pipeline::spectral {

struct ConfusionMatrix {
    std::vector<std::string> labels;      // the stored lights, then "unknown"
    std::vector<std::vector<int>> counts; // counts[true light][answer]
    int trials = 0;                       // per true light
};

// Single-sample answers (no hysteresis) for 'trials' noisy spectra of each stored light.
ConfusionMatrix classifierConfusion(const std::vector<StoredLight>& lights,
                                    const LightClassifierParams& params,
                                    const BandNoiseParams& noise,
                                    int trials,
                                    std::uint64_t seed);

// Number of changes of the hysteresis answer over a stream of 'samples' noisy spectra of one light
// after the first confirmation: 0 means no flicker.
int classifierFlicker(const std::vector<StoredLight>& lights,
                      const LightClassifierParams& params,
                      const BandNoiseParams& noise,
                      const Spectrum& truth,
                      int samples,
                      std::uint64_t seed);

// Shape distance of noisy readings of 'spd' from 'spd' itself: the given quantile (e.g. 0.999).
double noiseFloorDistance(const Spectrum& spd,
                          const BandNoiseParams& noise,
                          int trials,
                          double quantile,
                          std::uint64_t seed);

struct SeparableDifference {
    double mixFraction = 1.0;   // smallest alpha in (1 - alpha) L + alpha M no longer taken for L
    double shapeDistance = 0.0; // its shape distance from L
};

// The smallest mixture of 'other' into stored light 'index' (spectra normalised to equal Euclidean
// norm first) at which at most 1 % of noisy single samples are still classified as that light.
SeparableDifference minimumSeparableDifference(const std::vector<StoredLight>& lights,
                                               const LightClassifierParams& params,
                                               const BandNoiseParams& noise,
                                               std::size_t index,
                                               const Spectrum& other,
                                               int trials,
                                               std::uint64_t seed);

} // namespace replica::pipeline::spectral
