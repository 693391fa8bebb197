#!/usr/bin/env bash
# The kiosk from a site file on a cold shader cache, the sensors simulated (the booth's lamps in
# turn, 2 s each), for the ColorChecker (its plan: 24, 48 and 32 specular samples, looped at the
# specular grid's nodes) and the glossy cylinder (16 / 32 / 128 lights, 16 / 24 / 48 samples at
# its grid's nodes, every 2 texels): lamps that differ only in counts share one pass, so every lamp draws with the pass the
# first frame compiled. Checked from what field staff see: the log names one shading pass and one
# frame that compiled it (the first), the recording holds the lamp switches, and its replay draws
set -uo pipefail
replica="$1"
data="$2"
work="$3"
rm -rf "$work"
for scene in colorchecker glossy-cylinder; do
    out="$work/$scene"
    mkdir -p "$out/sessions" "$out/shader-cache"
    cat > "$out/site.toml" <<TOML
[run]
hal = "sim"
[scene]
dir = "$data/scenes/$scene"
[display]
output = "headless"
size = "240x150"
[recording]
directory = "$out/sessions"
TOML
    fail() {
        echo "FAIL: $scene: $*" >&2
        grep -E 'render|planner|error' "$out/run.log" >&2
        exit 1
    }
    # 330 frames at 60 Hz: 5.5 s of the scenario, the default lamp then three switches.
    MESA_SHADER_CACHE_DIR="$out/shader-cache" "$replica" --log-level info run --kiosk \
        --config "$out/site.toml" --frames 330 --fast > "$out/run.log" 2>&1 ||
        fail "the kiosk run failed"
    grep -q 'the other 0 compile after it' "$out/run.log" ||
        fail "the kiosk made more than one shading pass for the lamps"
    compiled=$(grep -c 'drew its shading pass for the first time' "$out/run.log")
    [ "$compiled" -eq 1 ] || fail "$compiled frames compiled a shading pass (want 1: the first)"
    grep -q 'frame [01] drew its shading pass for the first time' "$out/run.log" ||
        fail "the frame that compiled was not the first"
    rec=$(ls "$out"/sessions/*.mcap 2>/dev/null | head -1)
    [ -n "$rec" ] || fail "the kiosk wrote no session file"
    "$replica" inspect "$rec" --json > "$out/inspect.json" 2> "$out/inspect.log" ||
        fail "replica inspect refused $rec: $(cat "$out/inspect.log")"
    "$replica" replay "$rec" --json > "$out/replay.json" 2> "$out/replay.log" ||
        fail "replica replay of $rec failed: $(tail -3 "$out/replay.log")"
    python3 - "$out/inspect.json" "$out/replay.json" "$scene" <<'PY' || exit 1
import json, sys
scene = sys.argv[3]
lights = json.load(open(sys.argv[1]))["channels"]["/replica/light"]["count"]
if lights < 4:
    sys.exit(f"FAIL: {scene}: {lights} light decisions recorded; the default lamp and three "
             "switches make 4")
digests = json.load(open(sys.argv[2]))["display_digests"]
if digests["differing"] != 0 or digests["matched"] != 330:
    sys.exit(f"FAIL: {scene}: the replay's display digests: {digests} (want 330 matched, "
             "0 differing)")
print(f"PASS: {scene}: one shading pass for every lamp, compiled by the first frame; {lights} "
      "light decisions recorded; the replay matches all 330 display digests")
PY
done
