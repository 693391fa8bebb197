// Plain sample values produced by every device source (live, sim, replay) and written to
// recordings.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <string>
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

// Raw in, processed out: what a device gave before any processing, with the parameters the
// processing used. A driver attaches it to the sample it made from it; the recorder keeps it on
// /replica/raw/<device>, and 'replica replay --reprocess' re-derives the sample from it with
// today's code (platform/reprocess.*), so a processing fix applies to old field recordings.
// (A spectrum is raw already: SpectrumSample holds the counts and the EEPROM coefficients.)
struct RawTrackerInput {
    enum class Kind : std::uint8_t { OpentrackDatagram, HidReport };
    Kind kind = Kind::OpentrackDatagram;
    std::int64_t arrivalNs = 0;      // session time the bytes arrived
    std::vector<std::uint8_t> bytes; // the datagram, or the input report (report ID first when
                                     // the device numbers its reports) as hidapi gave it
    // HID: the report descriptor of this opening of the device (one object per opening).
    std::shared_ptr<const std::vector<std::uint8_t>> hidDescriptor;
    // Processing parameters. Opentrack: the mounting (hal/tracker/opentrack_udp.h); HID: device
    // axes to the tracker frame ("x,-y,z") and the timestamp re-anchoring threshold.
    double zSign = -1.0;
    glm::dvec3 eyeOffsetHeadM{0.0};
    std::string axes = "x,y,z";
    std::int64_t reanchorNs = 50'000'000;
};

// An IIO accelerometer's reading as sysfs gave it: in_accel_{x,y,z}_raw with the scale and
// offset read at open, and the mounting ("-y,x,z") that turns it into the panel frame.
struct RawAccelInput {
    std::array<double, 3> raw{};
    std::array<double, 3> scale{};
    std::array<double, 3> offset{};
    std::string axes = "x,y,z";
};

// The viewer's eye position as the head tracker reports it, in the tracker's own frame (metres).
struct PoseSample {
    std::int64_t timestampNs = 0;
    std::uint32_t sequence = 0;
    glm::dvec3 eyeTrackerM{0.0}; // tracker frame: x right, y up, z towards the viewer
    bool tracked = false;        // false while the markers are out of view
    std::shared_ptr<const RawTrackerInput> raw; // what the device sent; none for sim, staleness
};

// Gravity as the accelerometer on the display measures it (device frame, m/s^2).
struct AccelSample {
    std::int64_t timestampNs = 0;
    std::uint32_t sequence = 0;
    glm::dvec3 gravity{0.0};
    std::shared_ptr<const RawAccelInput> raw; // what sysfs gave; none when not recorded
};

// What the booth's lamp selector switch says, once its GPIO lines have settled (debounced).
// Wiring (hal/README.md): one line per lamp, in the booth's lamp order, active low with the
// pull-up on: the switch connects exactly one line to ground per lamp position, none at "off".
inline constexpr int kLampOff = -1;     // no line active: the switch is at "off"
inline constexpr int kLampInvalid = -2; // several lines active: a wiring fault or a broken switch
inline constexpr int kLampLost = -3;    // the lines cannot be read (chip unplugged, driver error)

struct LampSample {
    std::int64_t timestampNs = 0; // session time the position settled (last edge + debounce)
    std::uint32_t sequence = 0;
    int lamp = kLampOff;          // index into the booth's lamps, or kLampOff/Invalid/Lost
    std::uint32_t lineLevels = 0; // bit i: line i active (after debouncing), lines as configured
    std::uint32_t lineCount = 0;  // how many lines the selector has (at most 32)
};

inline const char* lampStateName(int lamp)
{
    return lamp >= 0              ? "lamp"
           : lamp == kLampOff     ? "off"
           : lamp == kLampInvalid ? "invalid"
                                  : "lost";
}

} // namespace replica::hal
