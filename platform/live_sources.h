// The live HAL: the real spectrometer (libusb), head tracker (opentrack UDP) and accelerometer
// (Linux IIO), the lamp selector (GPIO, when configured), wired to the pipeline's
// auto-integration controller.
#pragma once

#include <cstdint>
#include <filesystem>
#include <map>
#include <string>

#include <hal/clock.h>
#include <pipeline/base/expected.h>
#include <platform/appliance.h>

namespace replica::platform {

struct LiveOptions {
    // The devices opened live, by device kind name, and their live driver ('replica run
    // --spectrometer live --tracker hid ...'): spectrometer "live", tracker "opentrack" or "hid",
    // accel "live", lamp_selector "gpio". A site with a missing device runs that one on
    // simulation (or on a recording) and the rest live: makeLiveSources opens only these.
    std::map<std::string, std::string> devices{
            {"spectrometer", "live"}, {"tracker", "opentrack"}, {"accel", "live"}};
    std::string spectrometerSerial;    // the USB2000+ with this USB serial; empty = the first found
    std::string hidTracker;            // --tracker hid: /dev/hidrawN; empty = the first found
    std::string trackerAxes = "x,y,z"; // --tracker hid: device axis for x right, y up, z to viewer
    std::uint16_t trackerPort = 4242;
    std::string trackerBind = "127.0.0.1";
    std::filesystem::path iioRoot = "/sys/bus/iio/devices";
    std::string accelName;           // IIO 'name' attribute; empty = the first accelerometer
    std::string accelAxes = "x,y,z"; // see hal::accel::parseAxisMapping
    // The booth's lamp selector: "CHIP:OFF1,OFF2,..." (one line per lamp, lamp order); empty =
    // none (the spectrometer alone decides the light).
    std::string lampGpio;
};

// The devices marked live in 'options' (the others stay null for the caller to fill).
// Devices that are absent at start are not an error: their sources report Lost, retry in the
// background, and the loop keeps the last (or default) light, eye and tilt. Only a request that
// can never work (a tracker port in use, a bad address) fails here.
// lampCount: the booth's lamps, which the selector's lines must match one for one.
Expected<Sources>
makeLiveSources(const hal::Clock& clock, const LiveOptions& options, std::size_t lampCount = 3);

} // namespace replica::platform
