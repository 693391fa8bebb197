// Latest-sample semantics for the fixed-rate loop: keeps the newest sample of a device (and a short
// history, so replay can pick exactly the sample a recorded frame consumed), and counts sequence
// gaps.
#pragma once

#include <cstddef>
#include <cstdint>
#include <deque>
#include <optional>
#include <vector>

namespace replica::hal {

template <typename Sample>
class SampleLatch
{
public:
    explicit SampleLatch(std::size_t historyLength = 256) : capacity_(historyLength) {}

    // Takes freshly polled samples (time order). Returns how many samples the sequence numbers say
    // were lost since the previous one (0 when none).
    std::uint64_t push(const std::vector<Sample>& fresh)
    {
        std::uint64_t dropped = 0;
        for (const auto& s : fresh) {
            if (lastSequence_ && s.sequence > *lastSequence_ + 1) {
                dropped += s.sequence - *lastSequence_ - 1;
            }
            lastSequence_ = s.sequence;
            history_.push_back(s);
            if (history_.size() > capacity_) {
                history_.pop_front();
            }
        }
        return dropped;
    }

    // The newest sample, or nullptr before the first one. Held until a newer one arrives.
    const Sample* latest() const { return history_.empty() ? nullptr : &history_.back(); }

    // The retained sample with this sequence number, or nullptr.
    const Sample* find(std::uint32_t sequence) const
    {
        for (auto it = history_.rbegin(); it != history_.rend(); ++it) {
            if (it->sequence == sequence) {
                return &*it;
            }
        }
        return nullptr;
    }

private:
    std::size_t capacity_;
    std::deque<Sample> history_;
    std::optional<std::uint32_t> lastSequence_;
};

} // namespace replica::hal
