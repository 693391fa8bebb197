// The hand-over between a live driver's own thread and the loop: a bounded time-ordered queue that
// poll() drains without blocking, and an interruptible sleep that tells the thread when to stop.
#pragma once

#include <algorithm>
#include <chrono>
#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <mutex>
#include <vector>

namespace replica::hal {

template <typename Sample>
class LiveQueue
{
public:
    explicit LiveQueue(std::size_t capacity = 1024) : capacity_(std::max<std::size_t>(capacity, 1))
    {}

    // Appends a sample; when full, the oldest is dropped. Returns how many were dropped so far.
    std::uint64_t push(Sample s)
    {
        std::lock_guard lock(mutex_);
        if (queue_.size() >= capacity_) {
            queue_.pop_front();
            ++dropped_;
        }
        queue_.push_back(std::move(s));
        return dropped_;
    }

    // Moves every queued sample with timestampNs <= untilNs to 'out', oldest first.
    void drain(std::int64_t untilNs, std::vector<Sample>& out)
    {
        std::lock_guard lock(mutex_);
        while (!queue_.empty() && queue_.front().timestampNs <= untilNs) {
            out.push_back(std::move(queue_.front()));
            queue_.pop_front();
        }
    }

    // Sleeps up to ns (session time) or until stop(); false once stopped.
    bool waitFor(std::int64_t ns)
    {
        std::unique_lock lock(mutex_);
        return !wake_.wait_for(lock, std::chrono::nanoseconds(std::max<std::int64_t>(ns, 0)),
                               [this] { return stop_; });
    }

    void stop()
    {
        {
            std::lock_guard lock(mutex_);
            stop_ = true;
        }
        wake_.notify_all();
    }

    bool stopping() const
    {
        std::lock_guard lock(mutex_);
        return stop_;
    }

private:
    std::size_t capacity_;
    mutable std::mutex mutex_;
    std::condition_variable wake_;
    std::deque<Sample> queue_;
    std::uint64_t dropped_ = 0;
    bool stop_ = false;
};

} // namespace replica::hal
