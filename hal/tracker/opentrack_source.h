// The live head tracker: opentrack's UDP output received on its own thread. Works with any
// tracker opentrack drives (TrackIR through its NaturalPoint plugin, PointTracker webcams).
#pragma once

#include <cstdint>
#include <memory>
#include <string>

#include <hal/clock.h>
#include <hal/sources.h>
#include <hal/tracker/opentrack_udp.h>
#include <pipeline/base/expected.h>

namespace replica::hal::tracker {

struct OpentrackSourceOptions {
    std::string bindAddress = "127.0.0.1";
    std::uint16_t port = kOpentrackDefaultPort; // 0: any free port (tests)
    TrackerMounting mounting;
    std::int64_t staleNs = 500'000'000; // no pose for this long: Stalled, samples say untracked
    // At most one pose per this long: datagrams arriving faster (a flood, a misconfigured sender)
    // are coalesced, the latest of them kept and the rest counted. opentrack sends at its
    // tracker's rate, at most 250 Hz; 2 ms is 500 poses a second, under 10 per 60 Hz frame.
    // 0: every datagram its own pose.
    std::int64_t minIntervalNs = 2'000'000;
    // Coalesced and rejected datagrams are logged at most once per this long, with their counts.
    std::int64_t logIntervalNs = 10'000'000'000;
};

class OpentrackSource : public TrackerSource
{
public:
    virtual std::uint16_t boundPort() const = 0;
    // Datagrams that were not 48 finite bytes (wrong length, NaN or infinite values).
    virtual long rejectedDatagrams() const = 0;
    // Good datagrams replaced by a later one that arrived within minIntervalNs.
    virtual long coalescedDatagrams() const = 0;
};

// Binds the socket now (so a port clash is reported at start-up, naming the port) and starts the
// receiver thread.
Expected<std::unique_ptr<OpentrackSource>> makeOpentrackSource(const Clock& clock,
                                                               OpentrackSourceOptions options = {});

} // namespace replica::hal::tracker
