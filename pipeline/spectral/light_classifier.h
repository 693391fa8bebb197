// Picks which stored booth lamp is on from a sensed spectrum, or "unknown"; hysteresis stops noise
// from making the choice flicker.
#pragma once

#include <vector>

#include <pipeline/colour/spectrum.h>

namespace replica::pipeline::spectral {

class LightClassifier
{
public:
    // unknownAbove: distance beyond which no stored lamp is accepted; switchMargin: how much closer
    // a different lamp must be than the current one before the choice changes.
    explicit LightClassifier(std::vector<colour::Spectrum> lamps,
                             double unknownAbove = 0.10,
                             double switchMargin = 0.02);

    // Shape distance between two SPDs: both scaled to unit mean over the working grid, then the RMS
    // difference. 0 for identical shapes whatever their scale.
    static double shapeDistance(const colour::Spectrum& a, const colour::Spectrum& b);

    // The lamp index, or -1 for unknown. Stateful (hysteresis).
    int classify(const colour::Spectrum& sensed);
    int current() const { return current_; }

private:
    std::vector<colour::Spectrum> lamps_;
    double unknownAbove_;
    double switchMargin_;
    int current_ = -1;
};

} // namespace replica::pipeline::spectral
