// The cadence governor: whole divisors of the tick rate, chosen from the frames' own work times.
#include <algorithm>
#include <cmath>

#include <platform/loop/cadence.h>

namespace replica::platform {

CadenceGovernor::CadenceGovernor(std::int64_t periodNs, int maxDivisor)
    : periodMs_(static_cast<double>(std::max<std::int64_t>(periodNs, 1)) / 1e6),
      maxDivisor_(std::clamp(maxDivisor, 1, kMaxDivisor))
{}

int CadenceGovernor::divisorLimit(double rateHz, double minRateHz)
{
    if (!(rateHz > 0.0) || !(minRateHz > 0.0) || !std::isfinite(rateHz) || !(minRateHz < rateHz)) {
        return 1;
    }
    // A small tolerance so that 60 / 15 is 4 whatever the rounding of the figures given.
    const double n = std::floor(rateHz / minRateHz + 1e-9);
    return static_cast<int>(std::clamp(n, 1.0, static_cast<double>(kMaxDivisor)));
}

int CadenceGovernor::upWindow() const
{
    const double perSecond = 1000.0 / (divisor_ * periodMs_);
    return static_cast<int>(std::clamp(std::round(perSecond), static_cast<double>(kDownWindow),
                                       static_cast<double>(kUpWindow)));
}

double CadenceGovernor::recentPercentile(int n, double q) const
{
    std::array<double, kUpWindow> v{};
    for (int i = 0; i < n; ++i) {
        v[static_cast<std::size_t>(i)] =
                recent_[static_cast<std::size_t>((next_ - 1 - i + kUpWindow) % kUpWindow)];
    }
    const int rank = std::clamp(static_cast<int>(std::ceil(q * n)), 1, n);
    std::nth_element(v.begin(), v.begin() + (rank - 1), v.begin() + n);
    return v[static_cast<std::size_t>(rank - 1)];
}

bool CadenceGovernor::add(double workMs)
{
    if (maxDivisor_ == 1 || !std::isfinite(workMs) || workMs < 0.0) {
        return false;
    }
    recent_[static_cast<std::size_t>(next_)] = workMs;
    next_ = (next_ + 1) % kUpWindow;
    count_ = std::min(count_ + 1, kUpWindow);
    seen_ = std::min(seen_ + 1, kSettleFrames);
    if (seen_ < kSettleFrames) {
        return false;
    }
    int want = divisor_;
    if (count_ >= kDownWindow && divisor_ < maxDivisor_) {
        const double median = recentPercentile(kDownWindow, 0.5);
        if (median > kDownFit * divisor_ * periodMs_) {
            // Straight to the divisor the median fits, at least one step (a higher percentile
            // would count the run's first frames, which compile, as the scene's).
            const double fit = std::ceil(median / (kDownFit * periodMs_));
            want = std::clamp(static_cast<int>(std::min(fit, 1e6)), divisor_ + 1, maxDivisor_);
            decidedOnMs_ = median;
            decidedOver_ = kDownWindow;
        }
    }
    if (want == divisor_ && count_ >= upWindow() && divisor_ > 1) {
        const double p95 = recentPercentile(upWindow(), 0.95);
        const double fit = std::ceil(p95 / (kUpFit * periodMs_));
        if (fit < divisor_) {
            want = std::max(1, static_cast<int>(fit));
            decidedOnMs_ = p95;
            decidedOver_ = upWindow();
        }
    }
    if (want == divisor_) {
        return false;
    }
    divisor_ = want;
    count_ = 0; // the frames at the old cadence say nothing about the new one's
    next_ = 0;
    return true;
}

} // namespace replica::platform
