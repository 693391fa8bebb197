// Nearest-shape light classification with accept/release thresholds and a confirmation count.
#include <algorithm>
#include <cmath>
#include <limits>

#include <fmt/format.h>

#include <pipeline/spectral/light_classifier.h>

namespace replica::pipeline::spectral {
namespace {

std::vector<StoredLight> nameLamps(std::vector<colour::Spectrum> lamps)
{
    std::vector<StoredLight> out;
    for (std::size_t i = 0; i < lamps.size(); ++i) {
        out.push_back({fmt::format("lamp{}", i), lamps[i]});
    }
    return out;
}

double positiveSum(const Spectrum& s)
{
    double sum = 0.0;
    for (double v : s.v) {
        sum += std::max(v, 0.0);
    }
    return sum;
}

} // namespace

double spectralShapeDistance(const Spectrum& a, const Spectrum& b)
{
    // Sensor noise can make dark bands slightly negative; negative power is not a shape feature.
    const double sa = positiveSum(a);
    const double sb = positiveSum(b);
    if (!(sa > 0.0) || !(sb > 0.0) || !std::isfinite(sa) || !std::isfinite(sb)) {
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

LightClassifier::LightClassifier(std::vector<colour::Spectrum> lamps,
                                 double unknownAbove,
                                 double switchMargin)
    : lights_(nameLamps(std::move(lamps))), params_{unknownAbove, unknownAbove, switchMargin, 1}
{}

Expected<LightClassifier> LightClassifier::create(std::vector<StoredLight> lights,
                                                  const LightClassifierParams& params)
{
    if (lights.empty()) {
        return makeError(ErrorCode::InvalidArgument, "light classifier: no stored lights");
    }
    for (const auto& l : lights) {
        if (!(positiveSum(l.spd) > 0.0)) {
            return makeError(
                    ErrorCode::InvalidArgument,
                    fmt::format("light classifier: stored light '{}' has no energy", l.name));
        }
    }
    if (!(params.acceptDistance > 0.0) || !(params.releaseDistance >= params.acceptDistance) ||
        params.switchMargin < 0.0 || params.confirmSamples < 1) {
        return makeError(ErrorCode::InvalidArgument, "light classifier: need 0 < acceptDistance <= "
                                                     "releaseDistance, switchMargin >= 0 and "
                                                     "confirmSamples >= 1");
    }
    return LightClassifier(std::move(lights), params);
}

Classification LightClassifier::make(int index, double distance) const
{
    Classification c;
    c.index = index;
    c.name = index < 0 ? "unknown" : lights_[static_cast<std::size_t>(index)].name;
    c.distance = distance;
    return c;
}

Classification LightClassifier::nearest(const Spectrum& sensed) const
{
    int best = -1;
    double bestD = std::numeric_limits<double>::infinity();
    for (std::size_t i = 0; i < lights_.size(); ++i) {
        const double d = spectralShapeDistance(sensed, lights_[i].spd);
        if (d < bestD) {
            bestD = d;
            best = static_cast<int>(i);
        }
    }
    return make(bestD <= params_.acceptDistance ? best : -1, bestD);
}

Classification LightClassifier::update(const Spectrum& sensed)
{
    const Classification raw = nearest(sensed);
    int proposed = raw.index;
    double proposedD = raw.distance;
    if (current_.index >= 0) {
        const double dCurrent = spectralShapeDistance(
                sensed, lights_[static_cast<std::size_t>(current_.index)].spd);
        // Keep the current light while it still fits and nothing fits clearly better.
        if (dCurrent <= params_.releaseDistance &&
            (raw.index == current_.index || raw.distance > dCurrent - params_.switchMargin)) {
            proposed = current_.index;
            proposedD = dCurrent;
        }
    }
    if (proposed == current_.index) {
        candidate_ = -1;
        candidateCount_ = 0;
        current_.distance = proposedD;
        return current_;
    }
    if (proposed == candidate_) {
        ++candidateCount_;
    } else {
        candidate_ = proposed;
        candidateCount_ = 1;
    }
    if (candidateCount_ >= params_.confirmSamples) {
        current_ = make(proposed, proposedD);
        candidate_ = -1;
        candidateCount_ = 0;
    }
    return current_;
}

void LightClassifier::reset()
{
    current_ = Classification{};
    candidate_ = -1;
    candidateCount_ = 0;
}

void LightClassifier::restore(const LightClassifierState& s)
{
    const int n = static_cast<int>(lights_.size());
    current_ = s.current;
    if (current_.index < -1 || current_.index >= n) {
        current_ = Classification{};
    }
    // The candidate may be -1 too: "unknown" on its way to replacing a lamp.
    const bool valid = s.candidate >= -1 && s.candidate < n;
    candidate_ = valid ? s.candidate : -1;
    candidateCount_ = valid ? std::max(s.candidateCount, 0) : 0;
}

} // namespace replica::pipeline::spectral
