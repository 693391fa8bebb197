#!/usr/bin/env bash
# Tilt nodes measured (docs/rendering.md, "Tilt nodes"): each scene at 60 Hz on the simulator's
# default motion (the panel swinging), every tick drawn or skipped late (--min-rate 60: the
# cadence off, so the frames' own times show), with --tilt-nodes 0 and 2 interleaved A B B A per
# round, and for the frames drawn from tick FROM on: how many, their mean, median and 95th
# percentile, and how many took over the 16.7 ms period (the loop's debug log, nearest rank).
# Also the cadence the shipped floor (--min-rate 15) settles on with each, when CADENCE=1.
# Prints a Markdown table.
#   SCENES="colorchecker painting" FRAMES=900 FROM=300 ROUNDS=1 \
#       tests/benchmarks/tilt_nodes_table.sh REPLICA OUT
set -euo pipefail
replica="$1"
out="$2"
data="$(cd "$(dirname "$0")/../.." && pwd)/data"
mkdir -p "$out"
scenes=${SCENES:-colorchecker metamer painting glossy-cylinder}
frames=${FRAMES:-900}
from=${FROM:-300}
rounds=${ROUNDS:-1}
for scene in $scenes; do
    for r in $(seq 1 "$rounds"); do
        for nodes in 0 2 2 0; do
            tag="$scene-$nodes-$r-$RANDOM"
            "$replica" --log-level loop=debug run --hal sim --output headless \
                --scene "$data/scenes/$scene" --size 960x600 --rate 60 --frames "$frames" \
                --min-rate 60 --tilt-nodes "$nodes" --json > "$out/$tag.json" 2> "$out/$tag.log"
            echo "$scene $nodes $tag" >> "$out/runs.txt"
        done
    done
done
python3 - "$out" "$from" <<'PY'
import collections, json, math, re, sys
out, start = sys.argv[1], int(sys.argv[2])
rows = collections.defaultdict(list)
for line in open(f"{out}/runs.txt"):
    scene, nodes, tag = line.split()
    log = open(f"{out}/{tag}.log").read()
    times = [float(ms) for tick, ms in re.findall(r"\[loop\] \[debug\] frame (\d+): ([0-9.]+) ms", log)
             if int(tick) >= start]
    rows[(scene, nodes)].append(times)
def pct(v, p):
    s = sorted(v)
    return s[max(0, math.ceil(p / 100 * len(s)) - 1)]
print(f"| scene | --tilt-nodes | runs | frames drawn from tick {start} | mean ms | p50 | p95 | "
      "over 16.7 ms |")
print("|---|---|---|---|---|---|---|---|")
for (scene, nodes), runs in sorted(rows.items()):
    drawn = " / ".join(str(len(t)) for t in runs)
    mean = " / ".join(f"{sum(t) / len(t):.1f}" for t in runs)
    p50 = " / ".join(f"{pct(t, 50):.1f}" for t in runs)
    p95 = " / ".join(f"{pct(t, 95):.1f}" for t in runs)
    over = " / ".join(str(sum(1 for x in t if x > 1000 / 60)) for t in runs)
    print(f"| {scene} | {nodes} | {len(runs)} | {drawn} | {mean} | {p50} | {p95} | {over} |")
PY
