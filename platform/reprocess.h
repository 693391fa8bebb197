// Raw in, processed out: re-derives a recording's tracker and accelerometer samples from the raw
// inputs recorded beside them (format 5: /replica/raw/tracker, /replica/raw/accel) through
// today's processing code, so that a fix to processing applies to old field recordings
// ('replica replay --reprocess').
#pragma once

#include <cstddef>
#include <optional>
#include <string>

#include <pipeline/base/expected.h>
#include <recordings/recording.h>

namespace replica::platform {

struct ReprocessOptions {
    // Processing parameters to use instead of the recorded ones (each as its option reads it):
    // the HID tracker's axes ('--tracker-axes') and the accelerometer's mounting ('--accel-axes').
    std::optional<std::string> trackerAxes;
    std::optional<std::string> accelAxes;
};

struct ReprocessReport {
    std::size_t poses = 0, posesReprocessed = 0, posesChanged = 0;
    std::size_t accel = 0, accelReprocessed = 0, accelChanged = 0;
    // The lamp selector's recorded line levels (debounced; the raw edges are not recorded)
    // decoded again into a lamp; samples of lines lost have none.
    std::size_t lamp = 0, lampReprocessed = 0, lampChanged = 0;
    // HID reports whose device-clock time now maps to another session time than recorded. The
    // sample keeps its recorded time (when the loop received it, so the frames that used it
    // still find it); only its values are re-derived.
    std::size_t poseTimesDiffer = 0;
    // Samples whose re-derived values are not finite (an accelerometer scale of 1e308 overflows):
    // kept as they came out, which the loop ignores as it does a live device's NaN; counted so that
    // replay warns and its summary says how many.
    std::size_t posesNonFinite = 0, accelNonFinite = 0;
    // Accelerometer samples whose recorded scale or offset cannot be used (a scale that is not a
    // positive finite number: 0, NaN, inf; an offset that is not finite): their gravity is made
    // not finite (counted above too) rather than a zero vector that would pass for a tilt.
    std::size_t accelBadScale = 0;
    // The first accelerometer sample not finite, in words naming the device, the sample and the
    // values (empty: none), for replay's warning.
    std::string accelFirstNonFinite;
};

// Replaces the values of every sample that has a raw input with what today's code makes of it;
// samples without one (simulated devices, older formats, the tracker's staleness markers) stay as
// recorded. Fails with one line naming the sample when a raw input cannot be processed (a
// datagram of the wrong size, a descriptor that does not parse, a report that does not decode).
Expected<ReprocessReport> reprocess(recordings::Recording& rec, const ReprocessOptions& options);

} // namespace replica::platform
