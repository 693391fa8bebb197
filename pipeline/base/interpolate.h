// Linear interpolation in a table sampled on an increasing grid: the simulated spectrometer, the
// spectrometer's calibration and the sensed light's continuum read their tables with it.
#pragma once

#include <algorithm>
#include <cstddef>
#include <vector>

namespace replica::pipeline {

// What a table gives outside its grid.
enum class Outside {
    Zero,  // nothing there (no light, no response); also for a grid of fewer than 2 points
    Clamp, // the nearest end's value
};

// y at 'at' by linear interpolation between the grid points x (increasing, y.size() == x.size()).
inline double interpolateLinear(const std::vector<double>& x,
                                const std::vector<double>& y,
                                double at,
                                Outside outside)
{
    if (outside == Outside::Zero) {
        if (x.size() < 2 || at < x.front() || at > x.back()) {
            return 0.0;
        }
    } else {
        if (at <= x.front()) {
            return y.front();
        }
        if (at >= x.back()) {
            return y.back();
        }
    }
    const auto it = std::upper_bound(x.begin(), x.end(), at);
    if (it == x.end()) {
        return y.back();
    }
    const auto i = static_cast<std::size_t>(it - x.begin());
    const double t = (at - x[i - 1]) / (x[i] - x[i - 1]);
    return y[i - 1] + t * (y[i] - y[i - 1]);
}

} // namespace replica::pipeline
