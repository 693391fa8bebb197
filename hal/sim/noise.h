// Deterministic noise for simulators: the same seed gives the same numbers on every platform
// (std::normal_distribution is implementation-defined, so Box-Muller is written out).
#pragma once

#include <cmath>
#include <cstdint>
#include <numbers>

namespace replica::hal::sim {

class Noise
{
public:
    explicit Noise(std::uint64_t seed) : state_(seed) {}

    // Uniform in (0, 1), from splitmix64.
    double uniform()
    {
        state_ += 0x9e3779b97f4a7c15ULL;
        std::uint64_t z = state_;
        z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
        z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
        z ^= z >> 31;
        return (static_cast<double>(z >> 11) + 0.5) * (1.0 / 9007199254740992.0);
    }

    // Standard normal.
    double gaussian()
    {
        const double u1 = uniform();
        const double u2 = uniform();
        return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * std::numbers::pi * u2);
    }

private:
    std::uint64_t state_;
};

} // namespace replica::hal::sim
