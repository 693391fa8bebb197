// Debouncing and decoding of the lamp selector's lines.
#include <bit>

#include <hal/lamp/lamp_debouncer.h>
#include <hal/samples.h>

namespace replica::hal::lamp {

int decodeOneHot(std::uint32_t levels)
{
    if (levels == 0) {
        return kLampOff;
    }
    if (std::popcount(levels) != 1) {
        return kLampInvalid;
    }
    return std::countr_zero(levels);
}

std::uint32_t lineMask(std::size_t lineCount)
{
    return lineCount >= 32 ? 0xffffffffu : ((1u << lineCount) - 1u);
}

LampSample
settledSample(const SettledLevels& settled, std::uint32_t lineCount, std::uint32_t sequence)
{
    LampSample s;
    s.timestampNs = settled.settledNs;
    s.sequence = sequence;
    s.lineLevels = settled.levels & lineMask(lineCount);
    s.lineCount = lineCount;
    s.lamp = decodeOneHot(s.lineLevels);
    return s;
}

LampDebouncer::LampDebouncer(std::int64_t debounceNs) : debounceNs_(debounceNs > 0 ? debounceNs : 0)
{}

SettledLevels LampDebouncer::start(std::uint32_t levels, std::int64_t tNs)
{
    settled_ = levels;
    raw_ = levels;
    lastEdgeNs_ = tNs;
    pending_ = false;
    return {levels, tNs};
}

void LampDebouncer::observe(std::uint32_t levels, std::int64_t tNs)
{
    if (levels == raw_) {
        return; // an edge and its opposite between two reads: nothing changed for us
    }
    raw_ = levels;
    lastEdgeNs_ = tNs;
    // Bouncing back to the settled levels before the debounce time ends cancels the change.
    pending_ = raw_ != settled_;
}

std::optional<SettledLevels> LampDebouncer::settle(std::int64_t nowNs)
{
    if (!pending_ || nowNs - lastEdgeNs_ < debounceNs_) {
        return std::nullopt;
    }
    pending_ = false;
    settled_ = raw_;
    return SettledLevels{settled_, lastEdgeNs_ + debounceNs_};
}

std::optional<std::int64_t> LampDebouncer::dueNs() const
{
    if (!pending_) {
        return std::nullopt;
    }
    return lastEdgeNs_ + debounceNs_;
}

} // namespace replica::hal::lamp
