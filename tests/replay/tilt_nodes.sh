#!/usr/bin/env bash
# Tilt nodes (docs/rendering.md, "Tilt nodes") where the appliance runs: the diffuse term cached at
# multiples of 2 degrees and interpolated. The simulator's panel swings, so its frames use them.
#  1. 'replica run' records tilt_nodes_deg = 2 (the default) and replays bit for bit.
#  2. --tilt-nodes 0 records 0 and replays bit for bit; its frames differ from 1's once the panel
#     has moved (the option reaches the renderer), and agree on the first (drawn whole at the held
#     tilt either way).
#  3. The kiosk from a site file records 2 and its session replays matching its display digests.
#  4. A recording whose tilt_nodes_deg is out of range is refused by name.
#   tilt_nodes.sh REPLICA DATA_DIR WORK
set -uo pipefail
replica="$1"
data="$2"
work="$3"
rm -rf "$work" && mkdir -p "$work"
fail() {
    echo "FAIL: $*" >&2
    exit 1
}
common=(run --hal sim --output headless --scene "$data/scenes/painting" --size 320x200 --rate 30
        --frames 90 --fast)
recorded() { # the recording's tilt_nodes_deg
    "$replica" inspect "$1" --json | python3 -c 'import json,sys; print(json.load(sys.stdin)["config"].get("tilt_nodes_deg"))'
}
replays() { # replays recording $1 against its run's digests $2
    "$replica" --log-level warn replay "$1" --no-progress --check "$2" > "$1.replay.txt" 2>&1 ||
        fail "$1 does not replay to its digests: $(tail -5 "$1.replay.txt")"
    grep -q "^check: all [0-9]* frames match" "$1.replay.txt" ||
        fail "no match reported for $1: $(cat "$1.replay.txt")"
}

# 1 and 2.
for nodes in default 0; do
    extra=()
    [ "$nodes" = default ] || extra=(--tilt-nodes "$nodes")
    "$replica" "${common[@]}" "${extra[@]}" --record "$work/$nodes.mcap" \
        --digests "$work/$nodes.digests.json" > "$work/$nodes.log" 2>&1 ||
        fail "the run with --tilt-nodes $nodes failed: $(tail -3 "$work/$nodes.log")"
    replays "$work/$nodes.mcap" "$work/$nodes.digests.json"
done
got=$(recorded "$work/default.mcap")
[ "$got" = "2.0" ] || fail "a new run recorded tilt_nodes_deg = $got, not 2.0"
got=$(recorded "$work/0.mcap")
[ "$got" = "0.0" ] || fail "--tilt-nodes 0 recorded tilt_nodes_deg = $got, not 0.0"
python3 - "$work/default.digests.json" "$work/0.digests.json" <<'PY' || exit 1
import json, sys
def digests(path):
    d = json.load(open(path))
    frames = d["frames"] if isinstance(d, dict) else d
    return [f["xyz"] if isinstance(f, dict) and "xyz" in f else json.dumps(f, sort_keys=True)
            for f in frames]
a, b = digests(sys.argv[1]), digests(sys.argv[2])
if len(a) != len(b) or len(a) < 60:
    sys.exit(f"FAIL: {len(a)} and {len(b)} frames' digests")
if a[0] != b[0]:
    sys.exit("FAIL: the first frames differ: both draw the held tilt whole")
differ = sum(x != y for x, y in zip(a, b))
if differ < len(a) // 2:
    sys.exit(f"FAIL: only {differ} of {len(a)} frames differ with and without tilt nodes: "
             "the option does not reach the renderer")
print(f"run: tilt nodes recorded and replayed; {differ} of {len(a)} frames differ from --tilt-nodes 0")
PY

# 3. The kiosk path.
mkdir -p "$work/sessions"
cat > "$work/site.toml" <<TOML
[run]
hal = "sim"
rate_hz = 30.0
[scene]
dir = "scenes/painting"
[display]
output = "headless"
size = "320x200"
[recording]
directory = "$work/sessions"
TOML
"$replica" --log-level warn run --kiosk --config "$work/site.toml" --frames 90 --json \
    > "$work/kiosk.json" 2> "$work/kiosk.log" || fail "the kiosk run failed: $(tail -3 "$work/kiosk.log")"
rec=$(ls "$work"/sessions/*.mcap 2>/dev/null | head -1)
[ -n "$rec" ] || fail "the kiosk wrote no session file"
got=$(recorded "$rec")
[ "$got" = "2.0" ] || fail "the kiosk recorded tilt_nodes_deg = $got, not 2.0"
"$replica" replay "$rec" --json --no-progress > "$work/kiosk.replay.json" 2> "$work/kiosk.replay.log" ||
    fail "the kiosk's session does not replay: $(tail -3 "$work/kiosk.replay.log")"
python3 - "$work/kiosk.replay.json" "$work/kiosk.json" <<'PY' || exit 1
import json, sys
d = json.load(open(sys.argv[1]))["display_digests"]
frames = json.load(open(sys.argv[2]))["frames"]
if d["differing"] != 0 or d["matched"] != frames:
    sys.exit(f"FAIL: the kiosk session's replay: {d} (want {frames} matched, 0 differing)")
print(f"kiosk: tilt nodes recorded; all {frames} display digests match on replay")
PY

# 4. A recording asking for nodes 90 degrees apart: refused, naming the key (a recording without
#    the key, an older build's, replays without nodes: RunConfigSchema.TiltNodesAreRecorded...).
python3 "$(dirname "$0")/alter_recording.py" "$work/default.mcap" "$work/bad.mcap" \
    --config tilt_nodes_deg=90 || fail "could not alter the recording"
if "$replica" replay "$work/bad.mcap" --no-progress > "$work/bad.txt" 2>&1; then
    fail "a recording with tilt_nodes_deg = 90 replayed"
fi
out=$(cat "$work/bad.txt")
grep -q "/tilt_nodes_deg: expected a number in \[0, 10\], found 90" <<< "$out" ||
    fail "the refusal does not name the key: $out"
echo "PASS: tilt nodes are recorded, replay bit for bit, change the frames, and run on the kiosk path"
