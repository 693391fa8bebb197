// The live HAL: the real spectrometer (libusb), head tracker (opentrack UDP) and accelerometer
// (Linux IIO), wired to the pipeline's auto-integration controller.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>

#include <hal/clock.h>
#include <pipeline/base/expected.h>
#include <platform/appliance.h>

namespace replica::platform {

struct LiveOptions {
    std::uint16_t trackerPort = 4242;
    std::string trackerBind = "127.0.0.1";
    std::filesystem::path iioRoot = "/sys/bus/iio/devices";
    std::string accelName;           // IIO 'name' attribute; empty = the first accelerometer
    std::string accelAxes = "x,y,z"; // see hal::accel::parseAxisMapping
};

// Devices that are absent at start are not an error: their sources report Lost, retry in the
// background, and the loop keeps the last (or default) light, eye and tilt. Only a request that
// can never work (a tracker port in use, a bad address) fails here.
Expected<Sources> makeLiveSources(const hal::Clock& clock, const LiveOptions& options);

} // namespace replica::platform
