// Nearest-shape lamp classification with hysteresis.
#include <algorithm>
#include <cmath>
#include <limits>

#include <pipeline/spectral/light_classifier.h>

namespace replica::pipeline::spectral {

LightClassifier::LightClassifier(std::vector<colour::Spectrum> lamps,
                                 double unknownAbove,
                                 double switchMargin)
    : lamps_(std::move(lamps)), unknownAbove_(unknownAbove), switchMargin_(switchMargin)
{}

double LightClassifier::shapeDistance(const colour::Spectrum& a, const colour::Spectrum& b)
{
    // Sensor noise can make dark bands slightly negative; negative power is not a shape feature.
    double sa = 0.0;
    double sb = 0.0;
    for (std::size_t i = 0; i < colour::kBands; ++i) {
        sa += std::max(a[i], 0.0);
        sb += std::max(b[i], 0.0);
    }
    if (!(sa > 0.0) || !(sb > 0.0)) {
        return std::numeric_limits<double>::infinity();
    }
    const double n = static_cast<double>(colour::kBands);
    double sq = 0.0;
    for (std::size_t i = 0; i < colour::kBands; ++i) {
        const double d = std::max(a[i], 0.0) * n / sa - std::max(b[i], 0.0) * n / sb;
        sq += d * d;
    }
    return std::sqrt(sq / n);
}

int LightClassifier::classify(const colour::Spectrum& sensed)
{
    int best = -1;
    double bestDist = std::numeric_limits<double>::infinity();
    for (std::size_t i = 0; i < lamps_.size(); ++i) {
        const double d = shapeDistance(sensed, lamps_[i]);
        if (d < bestDist) {
            bestDist = d;
            best = static_cast<int>(i);
        }
    }
    if (!(bestDist <= unknownAbove_)) {
        best = -1;
    }
    if (current_ >= 0 && best != current_) {
        const double currentDist =
                shapeDistance(sensed, lamps_[static_cast<std::size_t>(current_)]);
        const bool currentStillFits = currentDist <= unknownAbove_;
        // Keep the current lamp unless the newcomer is clearly closer (or the current one no longer
        // fits).
        if (currentStillFits && (best < 0 || bestDist > currentDist - switchMargin_)) {
            return current_;
        }
    }
    current_ = best;
    return current_;
}

} // namespace replica::pipeline::spectral
