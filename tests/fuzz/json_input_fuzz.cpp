// Fuzz target for the text formats a person hands Replica: scene.json, booth.json, display
// profiles (JSON) and the CSV tables (spectral, display measurements, viewing angles). The first
// byte picks the format, the rest is the file. Every input must come back as a value or an Error,
// never an exception, abort or hang. With REPLICA_FUZZ_STANDALONE it links the plain driver
// standalone_driver.cpp: the corpus under json_corpus/ plus seeded random mutations with the
// tokens of json_input.dict (every CI build, any compiler); under clang the same entry point
// links libFuzzer (tests/fuzz/run_fuzz.sh, with the same dictionary).
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include <unistd.h>

#include <pipeline/booth/booth_model.h>
#include <pipeline/colour/spectral_table.h>
#include <pipeline/display/display_profile.h>
#include <pipeline/offline/display/measurement_set.h>
#include <pipeline/offline/display/viewing_angle_csv.h>
#include <pipeline/surface/surface_scene.h>

namespace {

// scene.json and booth.json are read from a folder: one scratch folder per process, removed at
// exit (the path is never destroyed, so the exit handler can still read it).
const std::filesystem::path& scratch()
{
    static const std::filesystem::path* const dir = [] {
        auto* d = new std::filesystem::path(std::filesystem::temp_directory_path() /
                                            ("replica-json-fuzz-" + std::to_string(::getpid())));
        std::filesystem::create_directories(*d);
        std::atexit([] {
            std::error_code ec;
            std::filesystem::remove_all(scratch(), ec);
        });
        return d;
    }();
    return *dir;
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
#include "standalone_driver.h"

// The standalone driver's mutations leave byte 0, which picks the format, alone.
const std::size_t replica::fuzz::kKeepPrefix = 1;
#endif
