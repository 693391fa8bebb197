#!/usr/bin/env bash
# Builds one fuzz target with clang and libFuzzer (ASan + UBSan) and fuzzes it for a bounded time,
# starting from its committed corpus (new finds go to a scratch corpus, not the repository).
#   run_fuzz.sh SOURCE_DIR WORK_DIR TARGET [SECONDS]      TARGET: mcap_reader or json_input
# The clang build is a CMake build tree under WORK_DIR/build (REPLICA_LIBFUZZER=ON), built once
# and then only where sources changed. Without clang and its fuzzer runtime (Debian's clang,
# libclang-rt-14-dev) it says so and exits 77 (ctest: skipped); the standalone corpus-and-mutations
# tests (fuzz.*_corpus) cover every compiler. Extra libFuzzer flags: FUZZ_FLAGS (e.g. -jobs=2).
set -euo pipefail
src="$1"
work="$2"
target="$3"
seconds="${4:-40}"
case "$target" in
mcap_reader) corpus="$src/tests/fuzz/corpus" dict="" max_len=32768 ;;
json_input) corpus="$src/tests/fuzz/json_corpus" dict="$src/tests/fuzz/json_input.dict" max_len=16384 ;;
hid_descriptor) corpus="$src/tests/fuzz/hid_corpus" dict="" max_len=4200 ;;
site_file) corpus="$src/tests/fuzz/site_corpus" dict="" max_len=8192 ;;
*) echo "run_fuzz.sh: unknown target '$target' (mcap_reader, json_input, hid_descriptor, site_file)" >&2; exit 2 ;;
esac
mkdir -p "$work/crashes/$target"
rm -rf "$work/scratch/$target" && mkdir -p "$work/scratch/$target"
cxx="${CLANGXX:-clang++}"
cc="${CLANGCC:-clang}"
probe="$work/probe.cpp"
echo 'extern "C" int LLVMFuzzerTestOneInput(const unsigned char*, unsigned long) { return 0; }' > "$probe"
if ! command -v "$cxx" >/dev/null 2>&1 || ! "$cxx" -fsanitize=fuzzer "$probe" -o "$work/probe" 2>/dev/null; then
    echo "SKIP: $cxx with -fsanitize=fuzzer is not available (apt-get install clang)"
    exit 77
fi
build="$work/build"
if [ ! -f "$build/build.ninja" ]; then
    # -O1 with line tables: fast enough to fuzz, readable stacks. Warnings are clang's, not
    # the project's compiler's: not errors here. Unity batches of 8, as the default preset: the
    # site file's target links all of platform/, whose file-by-file ASan build took over 900 s
    # on the loaded 2-core machine.
    cmake -S "$src" -B "$build" -G Ninja -DCMAKE_C_COMPILER="$cc" -DCMAKE_CXX_COMPILER="$cxx" \
        -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g" \
        -DCMAKE_UNITY_BUILD=ON -DCMAKE_UNITY_BUILD_BATCH_SIZE=8 -DREPLICA_WERROR=OFF -DREPLICA_SANITIZE=ON -DREPLICA_LIBFUZZER=ON \
        -DREPLICA_BUILD_BENCHMARKS=OFF >"$work/configure.log" 2>&1 ||
        { tail -20 "$work/configure.log"; exit 1; }
fi
cmake --build "$build" --target "replica_fuzz_$target" -j "${FUZZ_BUILD_JOBS:-2}" >"$work/build-$target.log" 2>&1 ||
    { tail -30 "$work/build-$target.log"; exit 1; }
# -max_len: a little above the largest seed, so mutations can grow files.
set +e
# shellcheck disable=SC2086
"$build/tests/fuzz/replica_fuzz_$target" -max_total_time="$seconds" -max_len="$max_len" \
    -timeout=10 -rss_limit_mb=2048 -artifact_prefix="$work/crashes/$target/" \
    -print_final_stats=1 ${dict:+-dict="$dict"} ${FUZZ_FLAGS:-} \
    "$work/scratch/$target" "$corpus" >"$work/fuzz-$target.log" 2>&1
rc=$?
set -e
tail -25 "$work/fuzz-$target.log"
if [ "$rc" -ne 0 ]; then
    echo "FAIL: libFuzzer found a problem in $target (exit $rc); the input is in $work/crashes/$target/"
    exit 1
fi
echo "PASS: fuzzed $target for ${seconds} s without a crash"
