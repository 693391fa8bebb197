// Classifier mode of the paper: which stored booth lamp is the sensed spectrum, or "unknown" (then
// the renderer uses the sensed spectrum itself: direct-sensor mode). Hysteresis keeps sensor noise
// from making the answer flicker.
#pragma once

#include <string>
#include <vector>

#include <pipeline/base/expected.h>
#include <pipeline/colour/spectrum.h>

namespace replica::pipeline::spectral {

using colour::Spectrum;

// Shape difference of two SPDs, blind to their scale (a dimmer or a longer integration does not
// change it): negative bands (sensor noise) are clamped to 0, each spectrum is scaled to unit mean
// over the 36 bands, and the result is the RMS difference. 0 for proportional spectra; infinity
// when either has no positive energy.
double spectralShapeDistance(const Spectrum& a, const Spectrum& b);

struct StoredLight {
    std::string name;
    Spectrum spd;
};

struct LightClassifierParams {
    // A lamp is recognised when the sensed shape is within acceptDistance of it...
    double acceptDistance = 0.05;
    // ...and, once recognised, kept while it stays within releaseDistance (>= acceptDistance) and
    // no other lamp is closer by more than switchMargin.
    double releaseDistance = 0.08;
    double switchMargin = 0.02;
    // A different answer must win this many consecutive samples before it replaces the current one
    // (1: at once).
    int confirmSamples = 3;
};

struct Classification {
    int index = -1;               // into the stored lamps; -1 = unknown
    std::string name = "unknown"; // the stored lamp's name, or "unknown"
    double distance = 0.0;        // shape distance to that lamp (to the nearest one when unknown)
};

// What the hysteresis remembers between samples: the answer, and a different one on its way to
// replacing it (how many samples in a row it has won). Saved at the head of a rotated session file
// and restored when that file is replayed alone (state/scene_estimator.h).
struct LightClassifierState {
    Classification current;
    int candidate = -1;
    int candidateCount = 0;
};

class LightClassifier
{
public:
    // The appliance's original form: lamps named "lamp0", "lamp1", ...; one threshold for accepting
    // and keeping (releaseDistance = acceptDistance = unknownAbove) and an answer that changes at
    // once (confirmSamples = 1). With no lamps every answer is unknown.
    explicit LightClassifier(std::vector<colour::Spectrum> lamps,
                             double unknownAbove = 0.10,
                             double switchMargin = 0.02);

    // The full form. Fails for an empty list, a lamp without energy, or thresholds out of order.
    static Expected<LightClassifier> create(std::vector<StoredLight> lights,
                                            const LightClassifierParams& params = {});

    static double shapeDistance(const colour::Spectrum& a, const colour::Spectrum& b)
    {
        return spectralShapeDistance(a, b);
    }

    // The nearest stored lamp, without memory: what a single sample says.
    Classification nearest(const Spectrum& sensed) const;
    // Feeds one sensed spectrum through the hysteresis and returns the current answer.
    Classification update(const Spectrum& sensed);
    // update(), returning the lamp index or -1 for unknown.
    int classify(const colour::Spectrum& sensed) { return update(sensed).index; }

    int current() const { return current_.index; }
    const Classification& currentClassification() const { return current_; }
    const std::vector<StoredLight>& lights() const { return lights_; }
    const LightClassifierParams& params() const { return params_; }
    void reset();
    LightClassifierState state() const { return {current_, candidate_, candidateCount_}; }
    // Restores a saved state; an index beyond the stored lamps is taken as unknown.
    void restore(const LightClassifierState& s);

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
