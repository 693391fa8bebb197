// Polling for a condition that a driver's reader thread brings about.
#pragma once

#include <chrono>
#include <thread>

namespace replica::tests {

// Waits up to 5 s for f() to hold; true as soon as it does.
template <typename F>
bool eventually(F f)
{
    for (int i = 0; i < 500; ++i) {
        if (f()) {
            return true;
        }
        std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    return false;
}

} // namespace replica::tests
