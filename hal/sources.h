// One interface per sample type; live, sim, recorded and replay implementations all fit them.
// Which devices exist (name, channel, codec) is data: recordings/device_kind.h.
#pragma once

#include <cstdint>
#include <vector>

#include <hal/device.h>
#include <hal/samples.h>

namespace replica::hal {

// Common shape: poll() appends every sample with timestampNs <= untilNs not yet returned, in time
// order, and never blocks. Live drivers fill a queue on their own thread; sim and replay sources
// compute or look up samples for the virtual time asked for.
// What every source says whatever it delivers (the loop and the run's report hold sources of
// different sample types side by side through it).
class AnySource
{
public:
    virtual ~AnySource() = default;
    virtual const DeviceInfo& info() const = 0;
    virtual LinkState state() const = 0;
};

template <typename Sample>
class Source : public AnySource
{
public:
    virtual void poll(std::int64_t untilNs, std::vector<Sample>& out) = 0;
};

using SpectrometerSource = Source<SpectrumSample>;
using TrackerSource = Source<PoseSample>;
using AccelSource = Source<AccelSample>;
using LampSelectorSource = Source<LampSample>;

} // namespace replica::hal
