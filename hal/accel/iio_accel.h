// Accelerometers through the Linux IIO subsystem (sysfs): finding the device, reading its raw
// counts with scale and offset, and the live source that samples it on its own thread.
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <glm/vec3.hpp>

#include <hal/clock.h>
#include <hal/sources.h>
#include <hal/sysfs_file.h>
#include <pipeline/base/expected.h>

namespace replica::hal::accel {

// One IIO device directory, e.g. /sys/bus/iio/devices/iio:device0, holding in_accel_* attributes.
class IioAccelDevice
{
public:
    // Opens 'dir' (a device directory), checking that it has in_accel_{x,y,z}_raw and a scale.
    static Expected<IioAccelDevice> open(const std::filesystem::path& dir);

    // The first device under 'root' (default /sys/bus/iio/devices) with accelerometer channels,
    // or the one whose 'name' attribute equals 'name' when given.
    static Expected<IioAccelDevice> find(const std::filesystem::path& root,
                                         const std::string& name = {});

    // a = (raw + offset) * scale per axis, m/s^2. Fails naming the attribute file if a read fails
    // (the device was removed, or the driver returned garbage).
    Expected<std::array<double, 3>> read() const;
    // The in_accel_{x,y,z}_raw values as sysfs gave them (before scale and offset).
    Expected<std::array<double, 3>> readRaw() const;

    const std::string& name() const { return name_; }
    const std::filesystem::path& dir() const { return dir_; }
    std::array<double, 3> scale() const { return scale_; }
    std::array<double, 3> offset() const { return offset_; }

private:
    std::filesystem::path dir_;
    std::string name_;
    std::array<double, 3> scale_{};
    std::array<double, 3> offset_{};
};

// One sysfs attribute's text (at most 64 bytes, up to its first newline), through
// hal::readSysfsFile: opened without waiting and read within kSysfsWaitMs, so that a FIFO, a
// device or a file that never answers in its place is an error, never a read that holds the
// source's thread (and SIGTERM) without end.
Expected<std::string> readSysfsText(const std::filesystem::path& file);
// Parses one sysfs attribute: a single C-locale number and a newline.
Expected<double> readSysfsNumber(const std::filesystem::path& file);

// A reading is used when its magnitude lies within these (m/s^2): a panel on its stand reads 1 g
// (9.81); below 0.25 g the tilt is undefined (a sensor stuck at zero, free fall), above 4 g it is
// a knock or a wrong scale. Outside, it is counted and logged like a reading that is not finite.
constexpr double kMinGravityMs2 = 0.25 * 9.80665;
constexpr double kMaxGravityMs2 = 4.0 * 9.80665;

// How the sensor is mounted on the panel: for each panel axis (x right, y up the panel, z out of
// the screen), which sensor axis and sign, e.g. "x,y,z" (aligned) or "-y,x,z".
struct AxisMapping {
    std::array<int, 3> axis{0, 1, 2};
    std::array<double, 3> sign{1.0, 1.0, 1.0};
};

Expected<AxisMapping> parseAxisMapping(const std::string& text);
// The text parseAxisMapping reads back: "x,y,z", "-y,x,z".
std::string toString(const AxisMapping& mapping);

// An accelerometer at rest reads the reaction to gravity (+1 g pointing up); the HAL's
// AccelSample carries gravity itself (pointing down) in the panel frame: -(mapped reading).
glm::dvec3 gravityInPanel(const std::array<double, 3>& reading, const AxisMapping& mapping);

// The whole processing of a raw reading: (raw + offset) * scale per axis, then the mounting.
// What the live source reports, and what 'replay --reprocess' recomputes from a recording.
glm::dvec3 gravityFromRaw(const RawAccelInput& raw, const AxisMapping& mapping);

struct IioAccelSourceOptions {
    AxisMapping mounting;
    std::filesystem::path root = "/sys/bus/iio/devices";
    std::string name;                   // the device's 'name' attribute; empty = the first
    std::int64_t periodNs = 10'000'000; // 100 Hz
    std::int64_t reconnectNs = 1'000'000'000;
    // The scale and offset are read again this often (a driver's range change alters them while
    // the device stays open): three small sysfs reads a second against 300 for the values.
    std::int64_t attributesNs = 1'000'000'000;
    // Readings that are not finite or out of range are counted and logged at most once per this
    // long.
    std::int64_t logIntervalNs = 10'000'000'000;
};

// Live source: reads the device at a fixed period on its own thread; if it disappears, reports
// Lost and looks for it again every second. Follows changes of the scale and offset; a reading
// that is not finite or out of range (kMinGravityMs2..kMaxGravityMs2) is counted, logged at a
// bounded rate and not used.
std::unique_ptr<AccelSource> makeIioAccelSource(const Clock& clock, IioAccelSourceOptions options);

} // namespace replica::hal::accel
