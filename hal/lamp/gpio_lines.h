// The seam between the lamp-selector driver and libgpiod: a set of requested GPIO lines that can
// be read and waited on for edges. The real adapter (libgpiod_lines.h) is a thin layer over
// libgpiod 1.6; tests drive the driver with a scripted fake of the same interface.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include <pipeline/base/expected.h>

namespace replica::hal::lamp {

// Which lines to watch: a chip (name "gpiochip0", number "0", or path "/dev/gpiochip0") and one
// line offset per booth lamp, in the booth's lamp order.
struct GpioLineSpec {
    std::string chip;
    std::vector<unsigned> offsets;
};

// Parses "CHIP:OFF1,OFF2,..." (e.g. "gpiochip0:17,27,22"): 1 to 32 distinct offsets.
Expected<GpioLineSpec> parseGpioLineSpec(const std::string& text);
std::string toString(const GpioLineSpec& spec);

// An edge on line 'line' (index into the spec's offsets, not the offset itself).
struct GpioEdge {
    std::size_t line = 0;
    bool active = false; // the level the line went to (logical: active = connected by the switch)
};

class GpioLines
{
public:
    virtual ~GpioLines() = default;
    // Where the lines are, for logs: "gpiochip0 [pinctrl-bcm2711] lines 17,27,22".
    virtual std::string describe() const = 0;
    // Current logical levels, bit i = line i active.
    virtual Expected<std::uint32_t> readLevels() = 0;
    // Waits up to timeoutNs for edges on any line and returns them in order (empty: timed out).
    // Fails when the chip has gone away or the kernel reports an error.
    virtual Expected<std::vector<GpioEdge>> waitEdges(std::int64_t timeoutNs) = 0;
};

// Requests the lines of a spec for edge events (both edges), active low with the pull-up, or
// says why not: no such chip, no such line, permission denied, line busy.
using GpioOpener = std::function<Expected<std::unique_ptr<GpioLines>>(const GpioLineSpec&)>;

} // namespace replica::hal::lamp
