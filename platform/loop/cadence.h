// A steady cadence for frames that take longer than the tick period: the loop then draws every
// n-th tick (rate_hz / n) for the smallest whole n that its frames fit, instead of drawing late
// ticks as they come. Late ticks alone make an uneven cadence: with 28 ms frames at 60 Hz the
// ticks drawn are 16.7 then 33.3 ms apart in turn while the panel shows a frame every 33.3 ms,
// so a moving eye or tilt steps unevenly (judder) and each frame shows a tick up to a period old.
// Every second tick is the same motion, even, each frame on time.
#pragma once

#include <array>
#include <cstdint>

namespace replica::platform {

class CadenceGovernor
{
public:
    // The longest step down: 1 / kMaxDivisor of the rate.
    static constexpr int kMaxDivisor = 8;
    // Frames the decisions look at: none before the run's first kSettleFrames (they compile
    // passes and fill caches: they would set a cadence the scene does not need); a step down
    // needs the median of the last kDownWindow frames over the cadence's period (a lamp change's
    // one slow frame does not move it; frames that take about the period keep it, drawn a little
    // late, on the same ticks: a frame late by a whole period is skipped in one cadence step); a
    // step up the 95th percentile (nearest rank) of the last upWindow() frames within 0.85 of the
    // faster period. The two thresholds leave a gap (a window whose 95th percentile is within
    // 0.85 of a period has its median within it), so the cadence does not swing between two.
    static constexpr int kSettleFrames = 30;
    static constexpr int kDownWindow = 12;
    static constexpr int kUpWindow = 48;
    static constexpr double kDownFit = 1.0;
    static constexpr double kUpFit = 0.85;

    // periodNs: the tick period; maxDivisor: the largest n allowed (1: never step down; clamped
    // to 1..kMaxDivisor).
    CadenceGovernor(std::int64_t periodNs, int maxDivisor);

    // One drawn frame's work (polling to hand-off, without waiting for the tick or the display's
    // flip). Returns true when the divisor changed.
    bool add(double workMs);

    int divisor() const { return divisor_; }
    int maxDivisor() const { return maxDivisor_; }
    double periodMs() const { return periodMs_; }
    // A second of frames at the cadence in force, kDownWindow to kUpWindow of them: a step up
    // follows a faster lamp's plan within about a second at any cadence.
    int upWindow() const;
    // The figure the last change was decided on (the window's median going down, its 95th
    // percentile going up), for the log.
    double decidedOnMs() const { return decidedOnMs_; }
    int decidedOverFrames() const { return decidedOver_; }

    // The largest n for a rate and the lowest rate allowed: floor(rate / minRate), at least 1
    // (a lowest rate at or above the rate, or not a positive number: 1).
    static int divisorLimit(double rateHz, double minRateHz);

private:
    // The q-th fraction (nearest rank) of the last n frames' times.
    double recentPercentile(int n, double q) const;

    double periodMs_;
    int maxDivisor_;
    int divisor_ = 1;
    std::array<double, kUpWindow> recent_{}; // a ring of the last frames at this divisor
    int count_ = 0;                          // frames at this divisor, up to kUpWindow
    int seen_ = 0;                           // frames in all, up to kSettleFrames
    int next_ = 0;
    double decidedOnMs_ = 0.0;
    int decidedOver_ = 0;
};

} // namespace replica::platform
