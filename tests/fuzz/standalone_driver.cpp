// See standalone_driver.h.
//
// Usage: FUZZER CORPUS_DIR [MUTATIONS_PER_FILE [SEED [DICTIONARY]]]
// DICTIONARY is a libFuzzer dictionary (lines name="text", with \\, \" and \xNN escapes); its
// entries are inserted by one of the mutations, as libFuzzer does with -dict.
#include "standalone_driver.h"

#include <array>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <random>
#include <string>
#include <vector>

namespace {

// The quoted text of each dictionary line; lines without a quoted value (comments) are skipped.
std::vector<std::string> readDictionary(const char* path)
{
    std::vector<std::string> tokens;
    std::ifstream in(path);
    std::string line;
    while (std::getline(in, line)) {
        const auto open = line.find('"');
        const auto close = line.rfind('"');
        if (line.empty() || line[0] == '#' || open == std::string::npos || close <= open) {
            continue;
        }
        std::string t;
        for (std::size_t k = open + 1; k < close; ++k) {
            if (line[k] != '\\' || k + 1 >= close) {
                t += line[k];
            } else if (line[k + 1] == 'x' && k + 3 < close) {
                t += static_cast<char>(std::strtol(line.substr(k + 2, 2).c_str(), nullptr, 16));
                k += 3;
            } else {
                t += line[++k];
            }
        }
        tokens.push_back(t);
    }
    return tokens;
}

} // namespace

int main(int argc, char** argv)
{
    if (argc < 2) {
        std::fprintf(stderr, "usage: %s CORPUS_DIR [MUTATIONS_PER_FILE [SEED [DICTIONARY]]]\n",
                     argv[0]);
        return 2;
    }
    const long mutations = argc > 2 ? std::strtol(argv[2], nullptr, 10) : 200;
    std::mt19937_64 rng(argc > 3 ? std::strtoull(argv[3], nullptr, 10) : 1);
    const std::vector<std::string> tokens =
            argc > 4 ? readDictionary(argv[4]) : std::vector<std::string>{};
    if (argc > 4 && tokens.empty()) {
        std::fprintf(stderr, "%s: no dictionary entries (name=\"text\" lines)\n", argv[4]);
        return 2;
    }
    std::vector<std::string> corpus;
    std::error_code ec;
    for (const auto& e : std::filesystem::directory_iterator(argv[1], ec)) {
        std::ifstream in(e.path(), std::ios::binary);
        corpus.emplace_back(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
    }
    if (ec || corpus.empty()) {
        std::fprintf(stderr, "%s: no corpus files there\n", argv[1]);
        return 2;
    }
    const std::size_t keep = replica::fuzz::kKeepPrefix;
    long runs = 0;
    auto run = [&](const std::string& s) {
        LLVMFuzzerTestOneInput(reinterpret_cast<const std::uint8_t*>(s.data()), s.size());
        ++runs;
    };
    for (const auto& seed : corpus) {
        run(seed);
        for (long k = 0; k < mutations; ++k) {
            std::string m = seed;
            // A few edits of the kinds that break containers and text formats: bit flips, byte
            // overwrites with boundary values, truncation, erasures, splices of another corpus
            // file and, given a dictionary, its tokens (wrong types, non-finite numbers, BOMs).
            const int edits = 1 + static_cast<int>(rng() % 4);
            const unsigned kinds = tokens.empty() ? 5 : 6;
            for (int e = 0; e < edits && m.size() > keep; ++e) {
                const std::size_t at = keep + rng() % (m.size() - keep);
                switch (rng() % kinds) {
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
                case 4: {
                    const auto& other = corpus[rng() % corpus.size()];
                    const std::size_t from = other.empty() ? 0 : rng() % other.size();
                    m.insert(at, other.substr(from, rng() % 256));
                    break;
                }
                default:
                    m.insert(at, tokens[rng() % tokens.size()]);
                }
            }
            run(m);
        }
    }
    std::printf("ok: %ld inputs (%zu corpus files, %ld mutations each), no crash\n", runs,
                corpus.size(), mutations);
    return 0;
}
