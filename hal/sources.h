// One interface per device kind; live, sim, recorded and replay implementations all fit them.
#pragma once

#include <cstdint>
#include <vector>

#include <hal/device.h>
#include <hal/samples.h>

namespace replica::hal {

// Common shape: poll() appends every sample with timestampNs <= untilNs not yet returned, in time
// order, and never blocks. Live drivers fill a queue on their own thread; sim and replay sources
// compute or look up samples for the virtual time asked for.
template <typename Sample>
class Source
{
public:
    virtual ~Source() = default;
    virtual const DeviceInfo& info() const = 0;
    virtual LinkState state() const = 0;
    virtual void poll(std::int64_t untilNs, std::vector<Sample>& out) = 0;
};

using SpectrometerSource = Source<SpectrumSample>;
using TrackerSource = Source<PoseSample>;
using AccelSource = Source<AccelSample>;
using LampSelectorSource = Source<LampSample>;

} // namespace replica::hal
