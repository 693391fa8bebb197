// Fuzz target for the recording reader: the checking MCAP scan (plain and resynchronising, as
// inspect and recover use it) and the JSON decoding of every message it accepts. Built with
// libFuzzer under clang (tests/fuzz/run_fuzz.sh); with REPLICA_FUZZ_STANDALONE it is a plain
// program that runs a corpus plus seeded random mutations (used by every CI build, any compiler).
#include <cstddef>
#include <cstdint>
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
        } catch (const nlohmann::json::exception&) {
            // A malformed payload is reported by the reader as damage; it must only not crash.
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
#include <array>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <random>
#include <string>
#include <vector>

// Usage: mcap_reader_fuzz CORPUS_DIR [MUTATIONS_PER_FILE [SEED]]
int main(int argc, char** argv)
{
    if (argc < 2) {
        std::fprintf(stderr, "usage: %s CORPUS_DIR [MUTATIONS_PER_FILE [SEED]]\n", argv[0]);
        return 2;
    }
    const long mutations = argc > 2 ? std::strtol(argv[2], nullptr, 10) : 200;
    std::mt19937_64 rng(argc > 3 ? std::strtoull(argv[3], nullptr, 10) : 1);
    std::vector<std::string> corpus;
    for (const auto& e : std::filesystem::directory_iterator(argv[1])) {
        std::ifstream in(e.path(), std::ios::binary);
        corpus.emplace_back(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
    }
    if (corpus.empty()) {
        std::fprintf(stderr, "%s: empty corpus\n", argv[1]);
        return 1;
    }
    long runs = 0;
    auto run = [&](const std::string& s) {
        LLVMFuzzerTestOneInput(reinterpret_cast<const std::uint8_t*>(s.data()), s.size());
        ++runs;
    };
    for (const auto& seed : corpus) {
        run(seed);
        for (long k = 0; k < mutations; ++k) {
            std::string m = seed;
            // A few edits of the kinds that break containers: bit flips, byte overwrites with
            // boundary values, truncation, and splices of another corpus file.
            const int edits = 1 + static_cast<int>(rng() % 4);
            for (int e = 0; e < edits && !m.empty(); ++e) {
                const std::size_t at = rng() % m.size();
                switch (rng() % 5) {
                case 0:
                    m[at] = static_cast<char>(m[at] ^ (1 << (rng() % 8)));
                    break;
                case 1:
                    m[at] = static_cast<char>(std::array<int, 4>{0, 0xff, 0x7f, 0x80}[rng() % 4]);
                    break;
                case 2:
                    m.resize(at);
                    break;
                case 3:
                    m.erase(at, rng() % 64);
                    break;
                default: {
                    const auto& other = corpus[rng() % corpus.size()];
                    const std::size_t from = other.empty() ? 0 : rng() % other.size();
                    m.insert(at, other.substr(from, rng() % 256));
                }
                }
            }
            run(m);
        }
    }
    std::printf("ok: %ld inputs (%zu corpus files, %ld mutations each), no crash\n", runs,
                corpus.size(), mutations);
    return 0;
}
#endif
