// The session's one time domain: monotonic nanoseconds since the session started.
#pragma once

#include <chrono>
#include <cstdint>

namespace replica::hal {

// Every sample and every frame tick is stamped in session-monotonic nanoseconds: 0 is the moment
// the session started, and time never goes backwards. Sim and replay sources run on virtual time,
// so the loop asks a Clock rather than the system for "now".
class Clock
{
public:
    virtual ~Clock() = default;
    virtual std::int64_t nowNs() const = 0;
};

// Wall-paced clock for live operation: steady_clock relative to construction.
class SteadyClock final : public Clock
{
public:
    SteadyClock() : start_(std::chrono::steady_clock::now()) {}
    std::int64_t nowNs() const override
    {
        return std::chrono::duration_cast<std::chrono::nanoseconds>(
                       std::chrono::steady_clock::now() - start_)
                .count();
    }

private:
    std::chrono::steady_clock::time_point start_;
};

// Virtual clock for simulation, replay and tests: time moves only when told to.
class VirtualClock final : public Clock
{
public:
    std::int64_t nowNs() const override { return nowNs_; }
    void set(std::int64_t ns) { nowNs_ = ns; }

private:
    std::int64_t nowNs_ = 0;
};

} // namespace replica::hal
