#!/usr/bin/env bash
# Replay speed per scene, as issue 35 asks for it: x real time (session seconds over wall seconds)
# of `replica replay` with the digests and the shown-frame check, against one or two builds.
#
#   tests/benchmarks/replay_speed.sh OUTDIR REPLICA_A [REPLICA_B]
#
# For each scene, A records a session: `REPLICA_A run --hal sim --output headless --scene S
# --rate RATE --frames FRAMES --size SIZE --fast --record OUTDIR/S.mcap` (the recording holds a
# display digest of every frame and a thumbnail a second, the defaults). Each binary then replays
# it, ROUNDS times, A B B A when there are two: `REPLICA replay OUTDIR/S.mcap --digests D.json
# --compare-shown --json --no-progress`, every frame's XYZ and display digests written and the
# recorded display digests and thumbnails checked; a replay that does not exit 0 or whose digests
# differ from the first replay's fails the script. Prints a markdown table, per scene and binary,
# the median over the rounds of: x real time of the frames (session seconds / the summary's
# wall_s, the frame loop and its checks), x real time of the whole command (start-up included:
# reading the file, building the scene, compiling the shaders), and the frame's mean ms.
# The environment may set SCENES ("colorchecker metamer painting"), SIZE (960x600), RATE (30),
# FRAMES (300), ROUNDS (2), REPLAY_ARGS (more replay options, e.g. --no-warm-up). Run it from the
# repository's root (the scenes are data/scenes/S).
set -uo pipefail

if [ $# -lt 2 ] || [ $# -gt 3 ] || [ "$1" = "-h" ] || [ "$1" = "--help" ]; then
    sed -n '2,19p' "$0" | sed 's/^# \{0,1\}//'
    exit 2
fi
out="$1"
bins=("$2")
[ $# -eq 3 ] && bins+=("$3")
for b in "${bins[@]}"; do
    if [ ! -x "$b" ]; then
        echo "replay_speed: $b is not an executable replica binary" >&2
        exit 1
    fi
done
scenes="${SCENES:-colorchecker metamer painting}"
size="${SIZE:-960x600}"
rate="${RATE:-30}"
frames="${FRAMES:-300}"
rounds="${ROUNDS:-2}"
read -r -a extra <<< "${REPLAY_ARGS:-}"
mkdir -p "$out" || exit 1
results="$out/results.tsv"
: > "$results"
failed=0

# One replay: appends "scene binary-index x_loop x_process mean_ms" to results.tsv.
replay_once() {
    local scene="$1" which="$2" round="$3"
    local bin="${bins[$which]}" tag="$out/$scene-$which-$round"
    local start=$EPOCHREALTIME
    "$bin" --log-level warn replay "$out/$scene.mcap" --digests "$tag.json" --compare-shown \
        --json --no-progress "${extra[@]}" > "$tag.summary.json" 2> "$tag.log"
    local code=$? end=$EPOCHREALTIME
    if [ "$code" -ne 0 ]; then
        echo "replay_speed: $scene with ${bins[$which]} exited $code; its log:" >&2
        tail -n 20 "$tag.log" >&2
        failed=1
        return
    fi
    if ! cmp -s "$tag.json" "$out/$scene-digests.json"; then
        if [ -e "$out/$scene-digests.json" ]; then
            echo "replay_speed: $scene with ${bins[$which]}: digests differ from the first replay's" >&2
            failed=1
        else
            cp "$tag.json" "$out/$scene-digests.json"
        fi
    fi
    python3 - "$tag.summary.json" "$start" "$end" "$rate" "$scene" "$which" >> "$results" <<'EOF'
import json, sys
s = json.load(open(sys.argv[1]))
start, end, rate = float(sys.argv[2]), float(sys.argv[3]), float(sys.argv[4])
session = s["frames_rendered"] / rate
assert s["display_digests"]["differing"] == 0, "display digests differ"
assert s["shown_check"]["result"] == "within_tolerance", "shown check failed"
print(f"{sys.argv[5]}\t{sys.argv[6]}\t{session / s['wall_s']:.3f}\t{session / (end - start):.3f}"
      f"\t{s['frame_time_ms']['mean']:.2f}\t{s['shown_check']['measured']}")
EOF
}

for scene in $scenes; do
    rm -f "$out/$scene-digests.json"
    if ! "${bins[0]}" --log-level warn run --hal sim --output headless --scene "data/scenes/$scene" \
        --rate "$rate" --frames "$frames" --size "$size" --fast --record "$out/$scene.mcap" \
        --force > "$out/$scene-record.log" 2>&1; then
        echo "replay_speed: recording $scene failed; its log:" >&2
        tail -n 20 "$out/$scene-record.log" >&2
        failed=1
        continue
    fi
    for ((r = 0; r < rounds; ++r)); do
        if [ ${#bins[@]} -eq 2 ]; then
            order=(0 1 1 0)
        else
            order=(0)
        fi
        for which in "${order[@]}"; do
            replay_once "$scene" "$which" "$r"
        done
    done
done

python3 - "$results" "${bins[@]}" <<'EOF'
import statistics, sys
rows = [l.split("\t") for l in open(sys.argv[1]).read().splitlines() if l]
bins = sys.argv[2:]
print("| scene | binary | x real time, frames (median) | x real time, whole command | "
      "frame ms mean | thumbnails checked | replays |")
print("|---|---|---|---|---|---|---|")
for scene in dict.fromkeys(r[0] for r in rows):
    for i, b in enumerate(bins):
        mine = [r for r in rows if r[0] == scene and r[1] == str(i)]
        if not mine:
            continue
        med = lambda k: statistics.median(float(r[k]) for r in mine)
        print(f"| {scene} | {'AB'[i]}: {b} | {med(2):.2f} | {med(3):.2f} | {med(4):.1f} | "
              f"{mine[0][5]} | {len(mine)} |")
EOF
exit "$failed"
