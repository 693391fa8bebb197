// Turns the raw, bouncing levels of the selector's lines into settled positions: a position counts
// once the levels have not changed for the debounce time. Pure and time-driven, so the live driver
// and the simulator share it and tests can feed it exact edge times.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>

#include <hal/samples.h>

namespace replica::hal::lamp {

// The lamp a one-hot level set selects: line i alone = lamp i; none = kLampOff; several =
// kLampInvalid.
int decodeOneHot(std::uint32_t levels);

// Contacts of panel switches bounce for 1 to 10 ms; 30 ms rides that out with margin while a turn
// of the knob still shows on screen in about two frames.
inline constexpr std::int64_t kDefaultDebounceNs = 30'000'000;

struct SettledLevels {
    std::uint32_t levels = 0;
    std::int64_t settledNs = 0; // when they became stable plus the debounce time
};

// The bits of a switch's lineCount lines (all 32 from 32 up).
std::uint32_t lineMask(std::size_t lineCount);

// The sample a settled position gives on a switch of lineCount lines (levels beyond them
// ignored): what the live driver and the simulator both report.
LampSample
settledSample(const SettledLevels& settled, std::uint32_t lineCount, std::uint32_t sequence);

class LampDebouncer
{
public:
    explicit LampDebouncer(std::int64_t debounceNs = kDefaultDebounceNs);

    // The levels read when the lines were opened: taken as settled at once.
    SettledLevels start(std::uint32_t levels, std::int64_t tNs);
    // The raw levels changed (an edge) at tNs.
    void observe(std::uint32_t levels, std::int64_t tNs);
    // If the raw levels have been stable for the debounce time by nowNs and differ from the last
    // settled ones, the new settled levels (returned once).
    std::optional<SettledLevels> settle(std::int64_t nowNs);
    // When settle() could next return something; nullopt when nothing is pending.
    std::optional<std::int64_t> dueNs() const;

    std::int64_t debounceNs() const { return debounceNs_; }

private:
    std::int64_t debounceNs_;
    std::uint32_t settled_ = 0;
    std::uint32_t raw_ = 0;
    std::int64_t lastEdgeNs_ = 0;
    bool pending_ = false;
};

} // namespace replica::hal::lamp
