// The tilt noise estimate: the median absolute second difference of the sensed tilts.
#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

#include <fmt/format.h>
#include <nlohmann/json.hpp>
#include <state/json_state.h>
#include <state/tilt_noise.h>

namespace replica::state {

namespace {

// median |d2| = 0.674490 sqrt(6) sigma for Gaussian noise (0.674490: the normal's 75th percentile).
constexpr double kMedianAbsD2PerSigma = 0.6744897501960817 * 2.449489742783178;

} // namespace

void TiltNoise::add(double tiltRad)
{
    if (!std::isfinite(tiltRad)) {
        return;
    }
    if (lastCount_ == 2) {
        absD2_[next_] = std::abs(tiltRad - 2.0 * last_[1] + last_[0]);
        next_ = (next_ + 1) % absD2_.size();
        count_ = std::min(count_ + 1, absD2_.size());
        estimate();
    }
    last_[0] = last_[1];
    last_[1] = tiltRad;
    lastCount_ = std::min<std::size_t>(lastCount_ + 1, 2);
}

void TiltNoise::estimate()
{
    if (count_ < kTiltNoiseMinSamples) {
        sigma_ = 0.0;
        return;
    }
    // The lower median (index (n - 1) / 2 of the sorted values): deterministic, and the choice
    // between the two middle values is well within the estimate's own scatter.
    std::array<double, kTiltNoiseWindow> sorted = absD2_;
    const auto end = sorted.begin() + static_cast<long>(count_);
    const auto mid = sorted.begin() + static_cast<long>((count_ - 1) / 2);
    std::nth_element(sorted.begin(), mid, end);
    sigma_ = *mid / kMedianAbsD2PerSigma;
}

nlohmann::json TiltNoise::save() const
{
    // The second differences oldest first, so that a restore need not know the ring's position.
    std::vector<double> d2;
    const std::size_t start = count_ < absD2_.size() ? 0 : next_;
    for (std::size_t i = 0; i < count_; ++i) {
        d2.push_back(absD2_[(start + i) % absD2_.size()]);
    }
    return {{"last", std::vector<double>(last_.end() - static_cast<long>(lastCount_), last_.end())},
            {"abs_d2", d2}};
}

Expected<void> TiltNoise::restore(const nlohmann::json& j)
{
    TiltNoise n;
    try {
        const auto& last = j.at("last");
        const auto& d2 = j.at("abs_d2");
        if (!last.is_array() || last.size() > 2 || !d2.is_array() || d2.size() > kTiltNoiseWindow) {
            throw std::out_of_range(fmt::format(
                    "the noise keeps at most 2 tilts and {} second differences", kTiltNoiseWindow));
        }
        n.lastCount_ = last.size();
        for (std::size_t i = 0; i < last.size(); ++i) {
            n.last_[2 - last.size() + i] = finiteFromJson(last[i]);
        }
        for (const auto& v : d2) {
            const double a = finiteFromJson(v);
            if (a < 0.0) {
                throw std::out_of_range("a second difference's magnitude is negative");
            }
            n.absD2_[n.count_++] = a;
        }
        n.next_ = n.count_ % kTiltNoiseWindow;
        n.estimate();
    } catch (const std::exception& e) {
        return makeError(ErrorCode::InvalidArgument, fmt::format("tilt noise: {}", e.what()));
    }
    *this = n;
    return {};
}

} // namespace replica::state
