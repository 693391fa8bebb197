// Classifier mode of the paper: which stored booth light is the sensed spectrum, or "unknown" (then
// the renderer uses the sensed spectrum itself: direct-sensor mode). Hysteresis keeps sensor noise
// from making the answer flicker.
#pragma once

#include <string>
#include <vector>

#include <pipeline/base/expected.h>
#include <pipeline/colour/spectrum.h>

namespace replica::pipeline::spectral {

using colour::Spectrum;

// Shape difference of two spectra, blind to their scale (a dimmer or a longer integration does not
// change it): the Euclidean distance between the spectra each divided by its own Euclidean norm,
// over the 36 bands. 0 for proportional spectra, sqrt(2) for spectra with no band in common. A
// spectrum with no positive energy is at distance sqrt(2) from everything.
double spectralShapeDistance(const Spectrum& a, const Spectrum& b);

struct StoredLight {
    std::string name;
    Spectrum spd;
};

struct LightClassifierParams {
    // A light is recognised when the sensed shape is within acceptDistance of it...
    double acceptDistance = 0.03;
    // ...and, once recognised, kept while it stays within releaseDistance (> acceptDistance) and no
    // other stored light is closer by more than switchMargin.
    double releaseDistance = 0.05;
    double switchMargin = 0.01;
    // A different answer must win this many consecutive samples before it replaces the current one.
    int confirmSamples = 3;
};

struct Classification {
    int index = -1;               // into the stored lights; -1 = unknown
    std::string name = "unknown"; // the stored light's name, or "unknown"
    double distance = 0.0;        // shape distance to that light (to the nearest one when unknown)
};

class LightClassifier
{
public:
    // Fails for an empty list, a stored light without energy, or thresholds out of order.
    static Expected<LightClassifier> create(std::vector<StoredLight> lights,
                                            const LightClassifierParams& params = {});

    // The nearest stored light, without memory: what a single sample says.
    Classification nearest(const Spectrum& sensed) const;
    // Feeds one sensed spectrum through the hysteresis and returns the current answer.
    Classification update(const Spectrum& sensed);
    const Classification& current() const { return current_; }
    const std::vector<StoredLight>& lights() const { return lights_; }
    void reset();

private:
    LightClassifier(std::vector<StoredLight> lights, const LightClassifierParams& params)
        : lights_(std::move(lights)), params_(params)
    {}
    Classification make(int index, double distance) const;

    std::vector<StoredLight> lights_;
    LightClassifierParams params_;
    Classification current_;
    int candidate_ = -1;
    int candidateCount_ = 0;
};

} // namespace replica::pipeline::spectral
