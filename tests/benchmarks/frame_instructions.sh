#!/usr/bin/env bash
# Instructions one appliance frame executes, llvmpipe's JIT shader code included, counted by
# callgrind: a figure that does not drift with the machine's load the way milliseconds do.
#
#   tests/benchmarks/frame_instructions.sh [--bench FILE] FILTER [NAME=VALUE ...]
#
# FILTER picks one loop benchmark (e.g. 'ApplianceFrame/2/0/-1/', the painting with the eye
# moving); NAME=VALUE pairs go into the environment of both runs. The benchmark runs twice under
# callgrind, once with one repetition of one iteration and once with four; the difference of the
# two totals is three frames, and set-up (scene loading, shader compiling) cancels. Mesa's shader
# cache is off so that both runs compile the same shaders. Needs valgrind; about two minutes on
# a 2-core machine for the painting.
set -euo pipefail

bench=build/default/tests/benchmarks/replica_bench_loop
if [ "${1:-}" = "--bench" ]; then
    bench="$2"
    shift 2
fi
if [ $# -lt 1 ] || [ "$1" = "-h" ] || [ "$1" = "--help" ]; then
    sed -n '2,12p' "$0" | sed 's/^# \{0,1\}//'
    exit 2
fi
filter="$1"
shift
if ! command -v valgrind > /dev/null; then
    echo "frame_instructions: valgrind is not installed (apt-get install valgrind)" >&2
    exit 1
fi
if [ ! -x "$bench" ]; then
    echo "frame_instructions: no benchmark at $bench (build it: cmake --build --preset default)" >&2
    exit 1
fi

work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
run() { # run REPS: writes $work/rREPS.log
    local reps="$1"
    shift
    env MESA_SHADER_CACHE_DISABLE=true "$@" valgrind --tool=callgrind \
        --callgrind-out-file="$work/r$reps.out" --smc-check=all "$bench" \
        --benchmark_filter="$filter" --benchmark_min_time=0.00001 \
        --benchmark_repetitions="$reps" > "$work/r$reps.log" 2>&1
}
total() {
    grep -m1 -o 'Collected : [0-9]*' "$work/r$1.log" | awk '{print $3}'
}
# The two runs side by side (valgrind runs a process on one core at a time).
run 1 "$@" &
pid=$!
status=0
run 4 "$@" || status=$?
wait "$pid" || status=$?
one=$(total 1 || true)
four=$(total 4 || true)
if [ "$status" -ne 0 ] || [ -z "$one" ] || [ -z "$four" ]; then
    echo "frame_instructions: the benchmark failed under valgrind; its output:" >&2
    tail -20 "$work/r1.log" "$work/r4.log" >&2
    exit 1
fi
echo "$filter: $(((four - one) / 3)) instructions per frame (1 repetition: $one, 4: $four)"
