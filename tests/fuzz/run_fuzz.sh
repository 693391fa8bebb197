#!/usr/bin/env bash
# Builds the reader's libFuzzer target with clang (ASan + UBSan) and fuzzes for a bounded time,
# starting from the committed corpus (new finds go to a scratch corpus, not the repository).
# Without clang and its fuzzer runtime it says so and exits 77 (ctest: skipped); the standalone
# corpus-and-mutations run (fuzz.mcap_reader_corpus) covers every compiler.
set -euo pipefail
src="$1"
work="$2"
seconds="${3:-45}"
rm -rf "$work/scratch" && mkdir -p "$work/scratch" "$work/crashes"
cxx="${CLANGXX:-clang++}"
probe="$work/probe.cpp"
echo 'extern "C" int LLVMFuzzerTestOneInput(const unsigned char*, unsigned long) { return 0; }' > "$probe"
if ! command -v "$cxx" >/dev/null 2>&1 || ! "$cxx" -fsanitize=fuzzer "$probe" -o "$work/probe" 2>/dev/null; then
    echo "SKIP: $cxx with -fsanitize=fuzzer is not available (apt-get install clang)"
    exit 77
fi
bin="$work/mcap_reader_fuzz"
# Rebuild only when a source changed.
sources=("$src/tests/fuzz/mcap_reader_fuzz.cpp" "$src"/recordings/mcap/*.cpp "$src/recordings/sample_codec.cpp")
if [ ! -x "$bin" ] || [ -n "$(find "${sources[@]}" "$src"/recordings/*.h "$src"/recordings/mcap/*.h -newer "$bin" 2>/dev/null)" ]; then
    "$cxx" -std=c++20 -O1 -g -fsanitize=fuzzer,address,undefined -fno-sanitize-recover=undefined \
        -I"$src" "$(pkg-config --cflags-only-I glm 2>/dev/null || true)" "${sources[@]}" \
        -o "$bin" -lfmt -lzstd -lz
fi
# -max_len: a little above the largest seed, so mutations can grow files.
"$bin" -max_total_time="$seconds" -max_len=32768 -timeout=10 -rss_limit_mb=2048 \
    -artifact_prefix="$work/crashes/" -print_final_stats=1 \
    "$work/scratch" "$src/tests/fuzz/corpus" 2>&1 | tail -15
echo "PASS: fuzzed the recording reader for ${seconds} s without a crash"
