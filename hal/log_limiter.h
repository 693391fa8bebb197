// One log line per interval for an event that can repeat without end (a flooding sender, a sensor
// reading NaN at 100 Hz, samples dropped every frame): the first occurrence is reported at once,
// later ones are counted and reported together at most once per interval, never one line each and
// never silence.
#pragma once

#include <cstdint>
#include <optional>

namespace replica::hal {

class LogLimiter
{
public:
    static constexpr std::int64_t kDefaultIntervalNs = 10'000'000'000; // 10 s

    explicit LogLimiter(std::int64_t intervalNs = kDefaultIntervalNs) : intervalNs_(intervalNs) {}

    // Counts n events at nowNs. Returns the number to report in one line when a line is due (the
    // first event ever, or the first after an interval since the last line), else 0.
    std::uint64_t add(std::uint64_t n, std::int64_t nowNs)
    {
        count(n);
        return flush(nowNs);
    }

    // Counts n events, reported by the next flush that is due.
    void count(std::uint64_t n)
    {
        pending_ += n;
        total_ += n;
    }

    // The events not yet reported, when a line is due; else 0. Call it now and then while quiet so
    // that the last events of a burst are reported within an interval.
    std::uint64_t flush(std::int64_t nowNs)
    {
        if (pending_ == 0 || (lastLineNs_ && nowNs - *lastLineNs_ < intervalNs_)) {
            return 0;
        }
        lastLineNs_ = nowNs;
        const std::uint64_t n = pending_;
        pending_ = 0;
        return n;
    }

    std::uint64_t total() const { return total_; }
    std::int64_t intervalNs() const { return intervalNs_; }

private:
    std::int64_t intervalNs_;
    std::optional<std::int64_t> lastLineNs_;
    std::uint64_t pending_ = 0;
    std::uint64_t total_ = 0;
};

} // namespace replica::hal
