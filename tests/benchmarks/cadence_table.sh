#!/usr/bin/env bash
# The steady cadence measured (platform/loop/cadence.h): each scene at 60 Hz on the simulator's
# default motion, once with the cadence (--min-rate 15, the shipped floor) and once without
# (--min-rate 60: late ticks skipped as they come), and for the ticks drawn from FROM on, how far
# apart they are: a steady cadence has one gap, an uneven one several. Prints a Markdown table.
#   SCENES="colorchecker metamer painting glossy-cylinder" FRAMES=900 FROM=300 \
#       tests/benchmarks/cadence_table.sh REPLICA OUT
set -euo pipefail
replica="$1"
out="$2"
data="$(cd "$(dirname "$0")/../.." && pwd)/data"
mkdir -p "$out"
scenes=${SCENES:-colorchecker metamer painting glossy-cylinder}
frames=${FRAMES:-900}
from=${FROM:-300}
for scene in $scenes; do
    for min in 15 60; do
        "$replica" --log-level loop=debug run --hal sim --output headless \
            --scene "$data/scenes/$scene" --size 960x600 --rate 60 --frames "$frames" \
            --min-rate "$min" --json > "$out/$scene-$min.json" 2> "$out/$scene-$min.log"
    done
done
python3 - "$out" "$from" $scenes <<'PY'
import collections, json, re, sys
out, start, scenes = sys.argv[1], int(sys.argv[2]), sys.argv[3:]
print("| scene | --min-rate | frames drawn | at each rate (Hz: frames) | gaps between drawn ticks "
      f"from tick {start} (ticks: count) | the commonest gap's share | frame ms p50 |")
print("|---|---|---|---|---|---|---|")
for scene in scenes:
    for m in ("15", "60"):
        j = json.load(open(f"{out}/{scene}-{m}.json"))
        drawn = [int(x) for x in re.findall(r"\[loop\] \[debug\] frame (\d+): [0-9.]+ ms",
                                          open(f"{out}/{scene}-{m}.log").read())]
        last = max(drawn)
        d = [x for x in drawn if start <= x < last]  # a fixed run always draws its last tick
        gaps = collections.Counter(b - a for a, b in zip(d, d[1:]))
        share = gaps.most_common(1)[0][1] / max(1, sum(gaps.values()))
        rates = ", ".join(f"{k}: {v}" for k, v in j["cadence"]["frames_at_hz"].items())
        hist = ", ".join(f"{k}: {v}" for k, v in sorted(gaps.items()))
        print(f"| {scene} | {m} | {j['frames']} | {rates} | {hist} | {share:.2f} | "
              f"{j['frame_time_ms']['p50']} |")
PY
