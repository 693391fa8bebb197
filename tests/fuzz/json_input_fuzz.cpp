// Fuzz target for the text formats a person hands Replica: scene.json, booth.json, display
// profiles (JSON) and the CSV tables (spectral, display measurements, viewing angles). The first
// byte picks the format, the rest is the file. Every input must come back as a value or an Error,
// never an exception, abort or hang. With REPLICA_FUZZ_STANDALONE it is a plain program that runs
// the corpus under json_corpus/ plus seeded random mutations (every CI build, any compiler); the
// same entry point builds under libFuzzer with clang.
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>

#include <unistd.h>

#include <pipeline/booth/booth_model.h>
#include <pipeline/colour/spectral_table.h>
#include <pipeline/display/display_profile.h>
#include <pipeline/display/measurement_set.h>
#include <pipeline/display/viewing_angle_csv.h>
#include <pipeline/surface/scene.h>

namespace {

// scene.json and booth.json are read from a folder: one scratch folder per process.
const std::filesystem::path& scratch()
{
    static const std::filesystem::path dir = [] {
        auto d = std::filesystem::temp_directory_path() /
                 ("replica-json-fuzz-" + std::to_string(::getpid()));
        std::filesystem::create_directories(d);
        return d;
    }();
    return dir;
}

} // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
    using namespace replica::pipeline;
    if (size == 0) {
        return 0;
    }
    const std::string text(reinterpret_cast<const char*>(data) + 1, size - 1);
    switch (data[0] % 6) {
    case 0:
        (void)display::profileFromJson(text, "fuzz.json");
        break;
    case 1:
        (void)colour::parseSpectralCsv(text, "fuzz.csv");
        break;
    case 2:
        (void)display::parseMeasurementCsv(text, "fuzz.csv");
        break;
    case 3:
        (void)display::parseViewingAngleCsv(text, "fuzz.csv");
        break;
    case 4:
        std::ofstream(scratch() / "scene.json", std::ios::binary | std::ios::trunc) << text;
        (void)surface::loadScene(scratch());
        break;
    default:
        std::ofstream(scratch() / "booth.json", std::ios::binary | std::ios::trunc) << text;
        (void)booth::loadBooth(scratch());
        break;
    }
    return 0;
}

#ifdef REPLICA_FUZZ_STANDALONE
#include <cstdio>
#include <cstdlib>
#include <iterator>
#include <random>
#include <vector>

// Usage: json_input_fuzz CORPUS_DIR [MUTATIONS_PER_FILE [SEED]]
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
    // Text-shaped edits: wrong types, non-finite and huge numbers, BOMs, quotes, truncation.
    const std::vector<std::string> tokens = {
            "null", "\"x\"", "5",     "-1",         "1e308", "-1e308", "NaN",  "[]",
            "{}",   "true",  "\"\"",  ",",          "\"",    "\n",     "\r\n", "\xEF\xBB\xBF",
            "[[[[", "0",     "65536", "4294967296", "..",    "/"};
    long runs = 0;
    auto run = [&](const std::string& s) {
        LLVMFuzzerTestOneInput(reinterpret_cast<const std::uint8_t*>(s.data()), s.size());
        ++runs;
    };
    for (const auto& seed : corpus) {
        run(seed);
        for (long k = 0; k < mutations; ++k) {
            std::string m = seed;
            const int edits = 1 + static_cast<int>(rng() % 4);
            for (int e = 0; e < edits && m.size() > 1; ++e) {
                const std::size_t at = 1 + rng() % (m.size() - 1); // byte 0 picks the format
                switch (rng() % 4) {
                case 0:
                    m[at] = static_cast<char>(m[at] ^ (1 << (rng() % 8)));
                    break;
                case 1:
                    m.resize(at);
                    break;
                case 2:
                    m.erase(at, rng() % 16);
                    break;
                default:
                    m.insert(at, tokens[rng() % tokens.size()]);
                }
            }
            run(m);
        }
    }
    std::filesystem::remove_all(scratch());
    std::printf("ok: %ld inputs (%zu corpus files, %ld mutations each), no crash\n", runs,
                corpus.size(), mutations);
    return 0;
}
#endif
