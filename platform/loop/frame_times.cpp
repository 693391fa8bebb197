// Frame-time statistics in fixed 0.25 ms bins.
#include <algorithm>
#include <cmath>

#include <platform/loop/frame_times.h>

namespace replica::platform {

void FrameTimes::add(double ms)
{
    if (!std::isfinite(ms) || ms < 0.0) {
        return;
    }
    const double bin = std::floor(ms / kBinMs);
    const std::size_t i =
            bin >= static_cast<double>(kBins - 1) ? kBins - 1 : static_cast<std::size_t>(bin);
    ++bins_[i];
    ++count_;
    sumMs_ += ms;
    maxMs_ = std::max(maxMs_, ms);
}

double FrameTimes::meanMs() const
{
    return count_ > 0 ? sumMs_ / static_cast<double>(count_) : 0.0;
}

double FrameTimes::percentileMs(double q) const
{
    if (count_ == 0) {
        return 0.0;
    }
    // The rank of the q-th frame in time order (1-based), at least the first.
    const double want =
            std::max(1.0, std::ceil(std::clamp(q, 0.0, 1.0) * static_cast<double>(count_)));
    std::uint64_t seen = 0;
    for (std::size_t i = 0; i < kBins; ++i) {
        seen += bins_[i];
        if (static_cast<double>(seen) >= want) {
            // The last bin also holds every frame past the top: only the maximum bounds it.
            return i + 1 == kBins ? maxMs_ : std::min(static_cast<double>(i + 1) * kBinMs, maxMs_);
        }
    }
    return maxMs_;
}

std::uint64_t FrameTimes::atLeast(double ms) const
{
    const double edge = std::ceil(std::max(ms, 0.0) / kBinMs);
    std::uint64_t n = 0;
    for (std::size_t i = static_cast<std::size_t>(std::min(edge, static_cast<double>(kBins)));
         i < kBins; ++i) {
        n += bins_[i];
    }
    return n;
}

} // namespace replica::platform
