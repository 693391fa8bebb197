#!/usr/bin/env bash
# The appliance's frame times per scene and size, as issue 35 measures them: one headless run each,
# per-frame times from the loop's debug log, the first frames left out, median / p90 / p95 / max.
#
#   tests/benchmarks/frame_table.sh REPLICA OUTDIR
#
# REPLICA: a replica binary; OUTDIR: where each run's log and the table (frames.md, frames.csv)
# go. Each run is `REPLICA --log-level loop=debug run --hal sim --output headless --scene S --rate
# RATE --frames FRAMES --size WxH [--fast]`; percentiles are nearest-rank, as the loop's own
# summary takes them. Prints the table (markdown) with each run's GL_RENDERER, the start-up's
# shader warm-up and the run's wall time (start-up included). The environment may set SCENES
# ("colorchecker painting metamer", folders of data/scenes), SIZES ("960x600 1920x1200"), PACING
# ("paced"; "fast" adds --fast, which skips the waits between frames), FRAMES (150), RATE (30),
# SKIP (20: frames left out at the start), RUN_TIMEOUT (600 s a run), MIN_RATE (unset: replica's
# default steady cadence, which draws every n-th tick where frames overrun the period; RATE: every
# tick, late ones skipped, as before the cadence: docs/appliance.md, "Steady cadence").
# The scenes are REPLICA_DATA_DIR/scenes/S when it is set, else data/scenes/S (run it from the
# repository's root). Exit 1 when any run failed (its row says so and its log's tail is printed).
set -uo pipefail

if [ $# -ne 2 ] || [ "$1" = "-h" ] || [ "$1" = "--help" ]; then
    sed -n '2,18p' "$0" | sed 's/^# \{0,1\}//'
    exit 2
fi
replica="$1"
out="$2"
if [ ! -x "$replica" ]; then
    echo "frame_table: $replica is not an executable replica binary" >&2
    exit 1
fi
scenes="${SCENES:-colorchecker painting metamer}"
sizes="${SIZES:-960x600 1920x1200}"
pacing="${PACING:-paced}"
frames="${FRAMES:-150}"
rate="${RATE:-30}"
skip="${SKIP:-20}"
run_timeout="${RUN_TIMEOUT:-600}"
for n in "$frames" "$rate" "$run_timeout"; do
    if ! [[ "$n" =~ ^[1-9][0-9]*$ ]]; then
        echo "frame_table: FRAMES, RATE and RUN_TIMEOUT must be positive whole numbers, not '$n'" >&2
        exit 1
    fi
done
if ! [[ "$skip" =~ ^[0-9]+$ ]] || ((skip >= frames)); then
    echo "frame_table: SKIP must be a whole number below FRAMES ($frames), not '$skip'" >&2
    exit 1
fi
for p in $pacing; do
    if [ "$p" != "paced" ] && [ "$p" != "fast" ]; then
        echo "frame_table: PACING items are 'paced' or 'fast', not '$p'" >&2
        exit 1
    fi
done
data="${REPLICA_DATA_DIR:-}"
mkdir -p "$out" || exit 1

failed=0
runs="$out/runs.txt"
: > "$runs"
for size in $sizes; do
    for scene in $scenes; do
        for p in $pacing; do
            scene_arg="${data:-data}/scenes/$scene"
            log="$out/$scene-$size-$p.log"
            args=(--log-level loop=debug run --hal sim --output headless --scene "$scene_arg"
                --rate "$rate" --frames "$frames" --size "$size")
            [ "$p" = "fast" ] && args+=(--fast)
            [ -n "${MIN_RATE:-}" ] && args+=(--min-rate "$MIN_RATE")
            echo "frame_table: $replica ${args[*]}" >&2
            start=$EPOCHREALTIME
            timeout "$run_timeout" "$replica" "${args[@]}" > "$log" 2>&1
            code=$?
            wall="$start $EPOCHREALTIME"
            printf '%s\t%s\t%s\t%s\t%s\t%s\n' "$scene" "$size" "$p" "$code" "$wall" "$log" >> "$runs"
            if [ "$code" -ne 0 ]; then
                failed=1
                echo "frame_table: exit $code ($scene $size $p); the log's end:" >&2
                tail -n 20 "$log" >&2
            fi
        done
    done
done

python3 - "$runs" "$out" "$skip" "$frames" "$rate" << 'PY'
import csv, math, re, sys

runs, out, skip, frames, rate = sys.argv[1], sys.argv[2], int(sys.argv[3]), sys.argv[4], sys.argv[5]
frame_re = re.compile(r"\[loop\] \[debug\] frame (\d+): ([0-9.]+) ms")
gl_re = re.compile(r"renderer=.* on ([^;]+); \d+x\d+ at ")
version_re = re.compile(r"\[info\] (replica [^;]+); data ")
warm_re = re.compile(r"(?:shading pass\(es\) warmed up|background compile of the other shading passes done) in (\d+) ms")


def rank(v, q):
    # Nearest rank, as platform/loop/frame_times.cpp takes it.
    return v[max(1, math.ceil(q * len(v))) - 1]


rows, versions = [], set()
for line in open(runs):
    scene, size, pacing, code, wall, log = line.rstrip("\n").split("\t")
    times, gl, warm = [], "?", ""
    for text in open(log, errors="replace"):
        m = frame_re.search(text)
        if m:
            times.append(float(m.group(2)))
            continue
        m = gl_re.search(text)
        if m:
            gl = m.group(1).strip()
        m = version_re.search(text)
        if m:
            versions.add(m.group(1))
        m = warm_re.search(text)
        if m:
            warm = f"{int(m.group(1)) / 1000:.1f}"
    kept = sorted(times[skip:])
    row = {"scene": scene, "size": size, "pacing": pacing, "gl_renderer": gl,
           "frames": len(kept), "median_ms": "", "p90_ms": "", "p95_ms": "", "max_ms": "",
           "warm_up_s": warm, "wall_s": f"{float(wall.split()[1]) - float(wall.split()[0]):.1f}",
           "status": "ok" if code == "0" else f"exit {code}"}
    if kept:
        row.update(median_ms=f"{rank(kept, 0.5):.1f}", p90_ms=f"{rank(kept, 0.9):.1f}",
                   p95_ms=f"{rank(kept, 0.95):.1f}", max_ms=f"{kept[-1]:.1f}")
    elif code == "0":
        # A paced run whose frames outlast the period skips ticks, and --frames counts ticks.
        row["status"] = (f"{len(times)} frames logged, none after the first {skip} (late frames "
                         "skip ticks: PACING=fast, or a quieter machine)")
    rows.append(row)

fields = list(rows[0].keys()) if rows else []
with open(f"{out}/frames.csv", "w", newline="") as f:
    w = csv.DictWriter(f, fieldnames=fields)
    w.writeheader()
    w.writerows(rows)
lines = [f"{', '.join(sorted(versions)) or 'replica ?'}; {frames} frames at {rate} Hz, the first "
         f"{skip} left out; ms per frame (nearest rank)", "",
         "| scene | size | pacing | GL_RENDERER | frames | median | p90 | p95 | max | warm-up s | run s | status |",
         "|---|---|---|---|---|---|---|---|---|---|---|---|"]
for r in rows:
    lines.append("| " + " | ".join(str(r[k]) for k in fields) + " |")
text = "\n".join(lines) + "\n"
open(f"{out}/frames.md", "w").write(text)
print(text, end="")
if any(r["status"] != "ok" for r in rows):
    sys.exit(1)
PY
table=$?
[ "$failed" -eq 0 ] && [ "$table" -eq 0 ]
