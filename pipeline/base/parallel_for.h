// Independent items spread over the machine's cores, for start-up work whose items share nothing
// (the booth dimmer's probe views, a relief's horizon map): each index is computed by exactly one
// thread and writes only its own slot, so the result is the same, bit for bit, whatever the thread
// count or order.
#pragma once

#include <algorithm>
#include <atomic>
#include <cstddef>
#include <exception>
#include <thread>
#include <vector>

namespace replica::pipeline {

// Calls body(i) for every i in [0, count), on up to maxThreads threads (0: one per core), the
// calling thread among them. The first exception a body throws is rethrown here once every
// thread has stopped; the items not yet started are then skipped.
template <typename Body>
void parallelFor(std::size_t count, const Body& body, unsigned maxThreads = 0)
{
    const unsigned cores = std::max(1u, std::thread::hardware_concurrency());
    const std::size_t threads =
            std::min<std::size_t>(count, maxThreads == 0 ? cores : std::max(1u, maxThreads));
    if (threads <= 1) {
        for (std::size_t i = 0; i < count; ++i) {
            body(i);
        }
        return;
    }
    std::atomic<std::size_t> next{0};
    std::atomic<bool> failed{false};
    std::exception_ptr error;
    std::atomic_flag errorTaken = ATOMIC_FLAG_INIT;
    const auto work = [&] {
        for (std::size_t i = next++; i < count && !failed; i = next++) {
            try {
                body(i);
            } catch (...) {
                if (!errorTaken.test_and_set()) {
                    error = std::current_exception();
                }
                failed = true;
            }
        }
    };
    std::vector<std::jthread> pool;
    pool.reserve(threads - 1);
    for (std::size_t t = 1; t < threads; ++t) {
        pool.emplace_back(work);
    }
    work();
    pool.clear(); // joins
    if (error) {
        std::rethrow_exception(error);
    }
}

} // namespace replica::pipeline
