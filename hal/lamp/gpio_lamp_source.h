// The live lamp selector: the booth's switch read through GPIO lines (libgpiod), debounced on the
// driver's own thread and queued for the loop like every live source. An unplugged chip, a
// missing line or a permission problem makes the source report Lost (one clear log line, a
// kLampLost sample) and retry every second; the appliance then runs on the spectrometer alone.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>

#include <hal/clock.h>
#include <hal/lamp/gpio_lines.h>
#include <hal/lamp/lamp_debouncer.h>
#include <hal/sources.h>

namespace replica::hal::lamp {

// The driver's logic without its thread: open the lines, read the position at open, then wait
// for edges, debounce and decode. Time comes from 'clock', so a test with a virtual clock and a
// scripted GpioLines runs it deterministically.
class LampSelectorReader
{
public:
    LampSelectorReader(std::unique_ptr<GpioLines> lines,
                       std::size_t lineCount,
                       const Clock& clock,
                       std::int64_t debounceNs = kDefaultDebounceNs);

    // The first sample: the levels read at open, taken as settled.
    Expected<LampSample> start(std::uint32_t sequence);
    // Waits at most maxWaitNs (less while a change is settling) for edges; returns a sample when a
    // new position has settled, nothing when none did, an error when the lines failed.
    Expected<std::optional<LampSample>> step(std::int64_t maxWaitNs, std::uint32_t sequence);

    const GpioLines& lines() const { return *lines_; }

private:
    std::unique_ptr<GpioLines> lines_;
    std::uint32_t lineCount_;
    std::uint32_t mask_;
    const Clock& clock_;
    LampDebouncer debouncer_;
};

struct GpioLampSourceOptions {
    GpioLineSpec lines;
    std::int64_t debounceNs = kDefaultDebounceNs;
    std::int64_t reconnectNs = 1'000'000'000;
    // How long one wait for edges may block: bounds how quickly the source stops.
    std::int64_t maxWaitNs = 50'000'000;
};

// Starts the driver thread at once; the first open happens on it. 'opener' is libgpiodOpener()
// for real hardware.
std::unique_ptr<LampSelectorSource>
makeGpioLampSource(GpioOpener opener, const Clock& clock, GpioLampSourceOptions options);

} // namespace replica::hal::lamp
