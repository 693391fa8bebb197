// The plain-program driver shared by the fuzz targets in this folder, for builds without
// libFuzzer (every CI build, any compiler): it runs each file of a corpus folder through the
// target's LLVMFuzzerTestOneInput, then seeded random mutations of it. Under clang the same
// targets link libFuzzer instead (REPLICA_LIBFUZZER, tests/fuzz/run_fuzz.sh).
#pragma once

#include <cstddef>
#include <cstdint>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size);

namespace replica::fuzz {

// Defined by each target: how many leading bytes of an input the mutations leave alone (e.g. a
// byte that picks the format).
extern const std::size_t kKeepPrefix;

} // namespace replica::fuzz
