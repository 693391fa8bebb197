// Simulated spectrometer, head tracker and accelerometer: real implementations of the HAL
// interfaces driven by the scripted scenario on virtual time, each on its own sample clock.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <hal/sim/scenario.h>
#include <hal/sources.h>
#include <pipeline/base/rigid_transform.h>

namespace replica::hal::sim {

// A lamp's relative spectral power on any increasing wavelength grid (nm).
struct SimLamp {
    std::string name;
    std::vector<double> wavelengthNm;
    std::vector<double> power;
};

struct SimSpectrometerParams {
    std::vector<SimLamp> lamps;         // indexed by the scenario's lamp number
    std::vector<double> responsivityNm; // detector + grating relative responsivity
    std::vector<double> responsivity;
    std::int64_t periodNs = 200'000'000; // about five spectra a second, as in the paper
    std::uint32_t integrationTimeUs = 100'000;
    double peakCounts = 40'000.0; // counts at the brightest pixel at the set integration time
    double darkCounts = 1'500.0;  // electrical offset
    double readNoiseCounts = 6.0;
    // Detector non-linearity: the counts above dark, m, compress as m = t / (1 - k t) for a linear
    // signal t; the EEPROM then carries the correction polynomial 1 + k m, which the chain inverts
    // exactly (t = m / (1 + k m)). -2e-6 compresses a 40 000-count peak by 7 %, typical of the
    // ILX511B before correction. 0 = linear.
    double nonlinearityK1 = -2.0e-6;
    std::uint64_t seed = 1;
};

// Simulated Ocean Optics USB2000+: 2048 pixels, a realistic wavelength polynomial, dark
// pixels 6..20 (masked on the detector), shot and read noise, detector non-linearity with its
// EEPROM correction coefficients, 16-bit saturation.
std::unique_ptr<SpectrometerSource> makeSimSpectrometer(ScenarioParams scenario,
                                                        SimSpectrometerParams params);

struct SimTrackerParams {
    std::int64_t periodNs = 8'333'333; // 120 Hz
    // T_booth_tracker the readings are simulated for: eye_tracker = its inverse of eye_booth.
    pipeline::RigidTransform trackerInBooth = pipeline::defaultTrackerInBooth();
    double jitterM = 0.0002;
    std::uint64_t seed = 2;
};

std::unique_ptr<TrackerSource> makeSimTracker(ScenarioParams scenario, SimTrackerParams params);

struct SimAccelParams {
    std::int64_t periodNs = 10'000'000; // 100 Hz
    double noiseMs2 = 0.02;
    std::uint64_t seed = 3;
};

// Gravity in the panel frame (x right, y up the panel, z out of the screen) for the scenario's
// tilt.
std::unique_ptr<AccelSource> makeSimAccel(ScenarioParams scenario, SimAccelParams params);

struct SimLampSelectorParams {
    // The line each scenario lamp's switch position connects (lamp i -> line wiring[i]); empty =
    // line i for lamp i. A permutation plays a mis-wired switch.
    std::vector<int> wiring;
    std::int64_t debounceNs = 30'000'000; // as the live driver (hal/lamp/lamp_debouncer.h)
    // Contact bounce at each turn of the knob: the old contact chatters as it breaks, the new one
    // makes contact after a short gap and chatters up to this long.
    std::int64_t bounceNs = 6'000'000;
    std::uint64_t seed = 4;
};

// The booth's lamp selector switch, turned at the instants the scenario changes lamps (so switch
// and light agree), with break-before-make and contact bounce that the same debouncer as the live
// driver removes. One line per lamp, one-hot.
std::unique_ptr<LampSelectorSource> makeSimLampSelector(ScenarioParams scenario,
                                                        SimLampSelectorParams params);

// The simulated detector's wavelength calibration (nm at pixel p = c0 + c1 p + c2 p^2 + c3 p^3).
constexpr double kSimWavelengthCoeffs[4] = {339.2, 0.3797, -1.62e-5, -1.3e-10};
constexpr int kSimPixels = 2048;
constexpr int kSimDarkPixelFirst = 6;
constexpr int kSimDarkPixelLast = 20;

} // namespace replica::hal::sim
