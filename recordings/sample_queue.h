// A bounded single-producer single-consumer queue whose push never blocks (it fails when full).
#pragma once

#include <atomic>
#include <cstddef>
#include <optional>
#include <utility>
#include <vector>

namespace replica::recordings {

template <typename T>
class SampleQueue
{
public:
    explicit SampleQueue(std::size_t capacity) : slots_(capacity > 0 ? capacity : 1) {}

    // Producer side: constructs the item in place. False (and nothing stored) when full.
    // (A forwarding reference: a device sample moved in is not copied again.)
    template <typename U>
    bool tryPush(U&& value)
    {
        const std::size_t tail = tail_.load(std::memory_order_relaxed);
        if (tail - head_.load(std::memory_order_acquire) == slots_.size()) {
            return false;
        }
        slots_[tail % slots_.size()].emplace(std::forward<U>(value));
        tail_.store(tail + 1, std::memory_order_release);
        return true;
    }

    // Consumer side.
    std::optional<T> tryPop()
    {
        const std::size_t head = head_.load(std::memory_order_relaxed);
        if (head == tail_.load(std::memory_order_acquire)) {
            return std::nullopt;
        }
        auto& slot = slots_[head % slots_.size()];
        std::optional<T> item = std::move(slot);
        slot.reset();
        head_.store(head + 1, std::memory_order_release);
        return item;
    }

    std::size_t capacity() const { return slots_.size(); }

private:
    std::vector<std::optional<T>> slots_;
    alignas(64) std::atomic<std::size_t> head_{0};
    alignas(64) std::atomic<std::size_t> tail_{0};
};

} // namespace replica::recordings
