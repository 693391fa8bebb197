#!/usr/bin/env bash
# Two builds of the loop benchmark timed against each other, interleaved, with the order
# alternating each round (A B, B A, A B, ...): on a machine whose speed drifts within the hour,
# a step is only seen when both sides share every spell.
#
#   tests/benchmarks/ab_loop.sh A_BENCH B_BENCH FILTER [ROUNDS]
#
# A_BENCH, B_BENCH: two replica_bench_loop binaries (e.g. one built in a `git worktree` of the
# older commit); FILTER: a --benchmark_filter, e.g. 'ApplianceFrame/[0-2]/0/-1/'; ROUNDS: default
# 6. Each run is --benchmark_min_time=1. Prints, per benchmark, the min / median of each side in
# ms of wall clock.
set -euo pipefail

if [ $# -lt 3 ] || [ "$1" = "-h" ] || [ "$1" = "--help" ]; then
    sed -n '2,11p' "$0" | sed 's/^# \{0,1\}//'
    exit 2
fi
a="$1"
b="$2"
filter="$3"
rounds="${4:-6}"
for bench in "$a" "$b"; do
    if [ ! -x "$bench" ]; then
        echo "ab_loop: $bench is not an executable benchmark" >&2
        exit 1
    fi
done
if ! [[ "$rounds" =~ ^[1-9][0-9]*$ ]]; then
    echo "ab_loop: ROUNDS must be a positive whole number, not '$rounds'" >&2
    exit 1
fi

raw=$(mktemp)
trap 'rm -f "$raw"' EXIT
for ((i = 1; i <= rounds; ++i)); do
    if ((i % 2 == 1)); then order="A B"; else order="B A"; fi
    for side in $order; do
        bench="$a"
        [ "$side" = "B" ] && bench="$b"
        "$bench" --benchmark_filter="$filter" --benchmark_min_time=1 --benchmark_format=csv \
            2> /dev/null | grep '^"BM' | awk -F, -v s="$side" '{gsub(/"/, "", $1); print s, $1, $3}' \
            >> "$raw"
    done
    echo "round $i of $rounds done" >&2
done
if [ ! -s "$raw" ]; then
    echo "ab_loop: no benchmark matched '$filter' (or none ran: no EGL/GLES?)" >&2
    exit 1
fi
python3 - "$raw" << 'PY'
import collections, sys
times = collections.defaultdict(list)
for line in open(sys.argv[1]):
    side, name, ms = line.split()
    times[(name, side)].append(float(ms))
for name in sorted({n for n, _ in times}):
    cols = []
    for side in "AB":
        v = sorted(times.get((name, side), []))
        cols.append(f"{side} {v[0]:.2f} / {v[len(v) // 2]:.2f}" if v else f"{side} -")
    print(f"{name}: " + "   ".join(cols) + " ms (min / median)")
PY
