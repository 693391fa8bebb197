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
};

class OpentrackSource : public TrackerSource
{
public:
    virtual std::uint16_t boundPort() const = 0;
    virtual long rejectedDatagrams() const = 0;
};

// Binds the socket now (so a port clash is reported at start-up, naming the port) and starts the
// receiver thread.
Expected<std::unique_ptr<OpentrackSource>> makeOpentrackSource(const Clock& clock,
                                                               OpentrackSourceOptions options = {});

} // namespace replica::hal::tracker
