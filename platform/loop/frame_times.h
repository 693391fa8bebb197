// How long the loop's frames take on the wall clock: count, mean, maximum and percentiles, in
// bounded memory (the kiosk runs for days). For the run's summary, never for a frame's content:
// the figures vary from run to run, the frames do not.
#pragma once

#include <array>
#include <cstdint>

namespace replica::platform {

class FrameTimes
{
public:
    // Bins of kBinMs up to kTopMs; a frame longer than that counts in the last bin (the maximum
    // keeps its exact value).
    static constexpr double kBinMs = 0.25;
    static constexpr double kTopMs = 500.0;

    // One frame of 'ms' milliseconds; a negative or non-finite time is ignored.
    void add(double ms);

    std::uint64_t count() const { return count_; }
    double meanMs() const;
    double maxMs() const { return maxMs_; }
    // The smallest bin edge at or below which a fraction q (0-1] of the frames fall: within
    // kBinMs above the exact percentile, and never above maxMs(). 0 with no frames.
    double percentileMs(double q) const;
    // How many frames took at least 'ms', rounded up to a bin edge (exact for a whole multiple of
    // kBinMs).
    std::uint64_t atLeast(double ms) const;

private:
    static constexpr std::size_t kBins = static_cast<std::size_t>(kTopMs / kBinMs);
    std::array<std::uint64_t, kBins> bins_{}; // 64-bit: a bin never wraps, however long the run
    std::uint64_t count_ = 0;
    double sumMs_ = 0.0;
    double maxMs_ = 0.0;
};

} // namespace replica::platform
