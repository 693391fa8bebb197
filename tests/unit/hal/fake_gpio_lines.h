// A scripted stand-in for the lamp selector's GPIO lines: level changes at given session times on
// a virtual clock, edge events as libgpiod would deliver them, and failures (chip removed) on cue.
#pragma once

#include <chrono>
#include <cstdint>
#include <deque>
#include <optional>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include <hal/clock.h>
#include <hal/lamp/gpio_lines.h>

namespace replica::tests {

class FakeGpioLines final : public hal::lamp::GpioLines
{
public:
    struct Change {
        std::int64_t tNs;
        std::uint32_t levels;
    };
    FakeGpioLines(hal::VirtualClock& clock, std::uint32_t initial, std::vector<Change> script)
        : clock_(clock), levels_(initial), script_(script.begin(), script.end())
    {}

    // Makes a wait without edges really sleep (for the threaded source, so it does not spin).
    void sleepWhenIdle() { sleeps_ = true; }

    // From tNs on, every call fails as a removed chip does.
    void failFrom(std::int64_t tNs, std::string message)
    {
        failAt_ = tNs;
        failMessage_ = std::move(message);
    }

    std::string describe() const override { return "fakechip [fake] lines 0..2"; }

    Expected<std::uint32_t> readLevels() override
    {
        ++reads_;
        if (failed()) {
            return makeError(ErrorCode::NotFound, failMessage_);
        }
        return levels_;
    }

    Expected<std::vector<hal::lamp::GpioEdge>> waitEdges(std::int64_t timeoutNs) override
    {
        ++waits_;
        maxTimeoutNs_ = std::max(maxTimeoutNs_, timeoutNs);
        const std::int64_t until = clock_.nowNs() + timeoutNs;
        if (failAt_ && *failAt_ <= until && (script_.empty() || *failAt_ <= script_.front().tNs)) {
            clock_.set(std::max(clock_.nowNs(), *failAt_));
            return makeError(ErrorCode::NotFound, failMessage_);
        }
        std::vector<hal::lamp::GpioEdge> edges;
        if (script_.empty() || script_.front().tNs > until) {
            clock_.set(until);
            if (sleeps_) {
                std::this_thread::sleep_for(std::chrono::nanoseconds(timeoutNs));
            }
            return edges;
        }
        // Every change at the same instant arrives together, one edge per line that moved.
        const std::int64_t t = script_.front().tNs;
        clock_.set(std::max(clock_.nowNs(), t));
        while (!script_.empty() && script_.front().tNs == t) {
            const std::uint32_t next = script_.front().levels;
            for (std::size_t i = 0; i < 32; ++i) {
                if (((levels_ ^ next) >> i) & 1u) {
                    edges.push_back({i, ((next >> i) & 1u) != 0});
                }
            }
            levels_ = next;
            script_.pop_front();
        }
        return edges;
    }

    int reads() const { return reads_; }
    int waits() const { return waits_; }
    std::int64_t maxTimeoutNs() const { return maxTimeoutNs_; }

private:
    bool failed() const { return failAt_ && clock_.nowNs() >= *failAt_; }

    hal::VirtualClock& clock_;
    std::uint32_t levels_;
    std::deque<Change> script_;
    std::optional<std::int64_t> failAt_;
    std::string failMessage_;
    int reads_ = 0;
    int waits_ = 0;
    bool sleeps_ = false;
    std::int64_t maxTimeoutNs_ = 0;
};

} // namespace replica::tests
