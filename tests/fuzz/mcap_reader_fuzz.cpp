// Fuzz target for the recording reader: the checking MCAP scan (plain and resynchronising, as
// inspect and recover use it) and the JSON decoding of every message it accepts. Built with
// libFuzzer under clang (tests/fuzz/run_fuzz.sh); with REPLICA_FUZZ_STANDALONE it links the plain
// driver standalone_driver.cpp: a corpus plus seeded random mutations (every CI build, any
// compiler).
#include <cstddef>
#include <cstdint>
#include <exception>
#include <string_view>

#include <nlohmann/json.hpp>

#include <recordings/mcap/reader.h>
#include <recordings/sample_codec.h>

namespace {

void decodeAll(const replica::recordings::mcap::Scan& s)
{
    using namespace replica::recordings;
    for (const auto& m : s.messages) {
        const auto it = s.channels.find(m.channelId);
        if (it == s.channels.end()) {
            __builtin_trap(); // the scan promises every message is on a known channel
        }
        const auto& topic = it->second.topic;
        try {
            const auto j = nlohmann::json::parse(m.data);
            int version = 0;
            if (topic == kSessionTopic) {
                (void)decodeSession(j, version);
            } else if (topic == kSpectrometerTopic) {
                (void)decodeSpectrum(j);
            } else if (topic == kTrackerTopic) {
                (void)decodePose(j);
            } else if (topic == kAccelTopic) {
                (void)decodeAccel(j);
            } else if (topic == kFrameTopic) {
                (void)decodeFrame(j);
            } else if (topic == kRecorderTopic) {
                (void)decodeRecorderStatus(j);
            }
        } catch (const std::exception&) {
            // A malformed payload (a JSON error, or an integer that does not fit: integerField's
            // std::out_of_range) is reported by the reader as damage; it must only not crash.
        }
    }
}

} // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
    using namespace replica::recordings;
    const std::string_view bytes(reinterpret_cast<const char*>(data), size);
    const auto plain = mcap::scan(bytes);
    decodeAll(plain);
    mcap::ScanOptions resync;
    resync.resync = true;
    for (const auto& d : channelDefinitions()) {
        resync.fallbackChannels[d.channel.id] = d.channel;
        resync.fallbackSchemas[d.schema.id] = d.schema;
    }
    const auto recovered = mcap::scan(bytes, resync);
    decodeAll(recovered);
    // Resynchronising never keeps fewer intact chunks than stopping at the first damage.
    if (recovered.chunks.size() < plain.chunks.size()) {
        __builtin_trap();
    }
    return 0;
}

#ifdef REPLICA_FUZZ_STANDALONE
#include "standalone_driver.h"

// The standalone driver's mutations may edit every byte of a recording.
const std::size_t replica::fuzz::kKeepPrefix = 0;
#endif
