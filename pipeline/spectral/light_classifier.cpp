// Nearest-shape light classification with accept/release thresholds and a confirmation count.
#include <cmath>
#include <limits>

#include <fmt/format.h>

#include <pipeline/spectral/light_classifier.h>

namespace replica::pipeline::spectral {
namespace {

constexpr double kSqrt2 = 1.4142135623730951;

double norm(const Spectrum& s)
{
    double n = 0.0;
    for (double v : s.v) {
        n += v * v;
    }
    return std::sqrt(n);
}

} // namespace

double spectralShapeDistance(const Spectrum& a, const Spectrum& b)
{
    const double na = norm(a);
    const double nb = norm(b);
    if (!(na > 0.0) || !(nb > 0.0) || !std::isfinite(na) || !std::isfinite(nb)) {
        return kSqrt2;
    }
    double d = 0.0;
    for (std::size_t i = 0; i < colour::kBands; ++i) {
        const double diff = a[i] / na - b[i] / nb;
        d += diff * diff;
    }
    return std::sqrt(d);
}

Expected<LightClassifier> LightClassifier::create(std::vector<StoredLight> lights,
                                                  const LightClassifierParams& params)
{
    if (lights.empty()) {
        return makeError(ErrorCode::InvalidArgument, "light classifier: no stored lights");
    }
    for (const auto& l : lights) {
        if (!(norm(l.spd) > 0.0) || l.spd.max() <= 0.0) {
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

} // namespace replica::pipeline::spectral
