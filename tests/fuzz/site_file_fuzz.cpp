// Fuzz target for the site-file reader (/etc/replica/replica.toml, what the kiosk reads at every
// start): any text is read into a configuration plus problems, or refused with one error naming
// the file; never a crash or an exception. Built with libFuzzer under clang
// (tests/fuzz/run_fuzz.sh); with REPLICA_FUZZ_STANDALONE it links standalone_driver.cpp.
#include <cstddef>
#include <cstdint>
#include <string>

#include <platform/site_config.h>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
    const std::string text(reinterpret_cast<const char*>(data), size);
    const auto site = replica::platform::parseSiteConfig(text, "fuzz.toml");
    if (!site && site.error().message.rfind("fuzz.toml", 0) != 0) {
        __builtin_trap(); // every refusal names the file first
    }
    return 0;
}

#ifdef REPLICA_FUZZ_STANDALONE
#include "standalone_driver.h"

const std::size_t replica::fuzz::kKeepPrefix = 0;
#endif
