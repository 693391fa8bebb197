// Plain sample values produced by every device source (live, sim, replay) and written to
// recordings.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include <glm/vec3.hpp>

namespace replica::hal {

// One raw spectrum as the spectrometer delivers it, with everything needed to turn the counts into
// a spectral power distribution later (the conversion lives in pipeline/, not here).
struct SpectrumSample {
    std::int64_t timestampNs = 0; // session time the spectrum became available
    std::uint32_t sequence = 0;   // per-source counter; gaps mean drops
    std::uint32_t integrationTimeUs = 0;
    std::vector<std::uint16_t> counts; // one per detector pixel, pixel 0 first
    // Wavelength of pixel p: c0 + c1 p + c2 p^2 + c3 p^3 (nm), from the device's EEPROM.
    std::array<double, 4> wavelengthCoeffs{};
    // Counts correction polynomial in raw counts (non-linearity), order 0..7, from the EEPROM.
    std::array<double, 8> nonlinearityCoeffs{};
    bool saturated = false; // any pixel at the detector's full scale
};

// The viewer's eye position as the head tracker reports it, in the tracker's own frame (metres).
struct PoseSample {
    std::int64_t timestampNs = 0;
    std::uint32_t sequence = 0;
    glm::dvec3 eyeTrackerM{0.0}; // tracker frame: x right, y up, z towards the viewer
    bool tracked = false;        // false while the markers are out of view
};

// Gravity as the accelerometer on the display measures it (device frame, m/s^2).
struct AccelSample {
    std::int64_t timestampNs = 0;
    std::uint32_t sequence = 0;
    glm::dvec3 gravity{0.0};
};

} // namespace replica::hal
