// The accelerometer's tilt noise, measured from the sensed tilts themselves, so that the hold
// filter's thresholds fit the sensor a site has rather than the one they were designed for.
#pragma once

#include <array>
#include <cstddef>

#include <nlohmann/json_fwd.hpp>

#include <pipeline/base/expected.h>

namespace replica::state {

// Second differences x[n] - 2 x[n-1] + x[n-2] of successive samples: a panel standing still or
// turning at a steady rate leaves only the noise in them, with variance 6 sigma^2. Their median
// absolute value over the last kTiltNoiseWindow samples is 0.6745 sqrt(6) sigma for Gaussian noise,
// and a step (someone turning the panel) moves it by at most two of its places. Over 64 samples
// the estimate scattered 17 % (its extremes 0.67 and 1.64 of the truth over 4000 samples), so a
// threshold set from it would swing with it; over 256 (about 4 s at 60 Hz) 7-9 %, extremes 0.81
// and 1.27.
constexpr std::size_t kTiltNoiseWindow = 256;
// Until the window is full the estimate is none (0) and the fixed thresholds apply: over fewer
// samples it scatters more (over 32, 0.6-1.5 of the truth), and a design sensor's estimate would
// cross the threshold that keeps its fixed thresholds (tilt_estimator.h, kTiltNoiseFitRad).
constexpr std::size_t kTiltNoiseMinSamples = kTiltNoiseWindow;

class TiltNoise
{
public:
    // A usable sensed tilt (finite, radians), in the order the sensor gave them.
    void add(double tiltRad);
    // The noise's standard deviation per sample, radians; 0 until kTiltNoiseMinSamples of them.
    double sigmaRad() const { return sigma_; }

    nlohmann::json save() const;
    Expected<void> restore(const nlohmann::json& j);

private:
    std::array<double, 2> last_{}; // the two previous tilts, the older first
    std::size_t lastCount_ = 0;
    std::array<double, kTiltNoiseWindow> absD2_{};
    std::size_t next_ = 0;
    std::size_t count_ = 0;
    double sigma_ = 0.0;

    void estimate();
};

} // namespace replica::state
