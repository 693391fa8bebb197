// The real GpioLines: libgpiod 1.6 (the v1 C API Debian 12 ships), as thin as it can be; every
// decision (debounce, decoding, retries) lives above it in gpio_lamp_source.
#pragma once

#include <string>
#include <vector>

#include <hal/lamp/gpio_lines.h>

namespace replica::hal::lamp {

// Opens the spec's chip and requests its lines for both-edge events, active low with the pull-up
// (without the pull-up on kernels that cannot set bias: then the board needs external pull-ups).
// Errors name the chip and line and say what to do: no such chip, no such line, permission denied
// (deploy/udev/60-replica.rules and the plugdev group), line in use.
GpioOpener libgpiodOpener();

// One GPIO chip as 'replica probe' lists it.
struct GpioChipInfo {
    std::string path;  // /dev/gpiochipN
    std::string name;  // gpiochipN
    std::string label; // the driver's label, e.g. pinctrl-bcm2711
    unsigned lines = 0;
    std::string error; // not empty: the chip could not be opened (why, and what to do)
};
std::vector<GpioChipInfo> listGpioChips(const std::string& devDir = "/dev");

} // namespace replica::hal::lamp
