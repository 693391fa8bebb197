#!/usr/bin/env bash
# The kiosk from a site file on a cold shader cache, the sensors simulated (the booth's lamps in
# turn, 2 s each): the ColorChecker's plan gives its lamps 24, 48 and 32 specular samples, counts
# its pass only loops to at the specular grid's nodes, so every lamp draws with the one pass the
# first frame compiled. Checked from what field staff see: the log names one shading pass and one
# frame that compiled it (the first), the recording holds the lamp switches, and its replay draws
# the same display digests bit for bit.
set -uo pipefail
replica="$1"
data="$2"
work="$3"
rm -rf "$work" && mkdir -p "$work/sessions" "$work/shader-cache"
cat > "$work/site.toml" <<TOML
[run]
hal = "sim"
[scene]
dir = "$data/scenes/colorchecker"
[display]
output = "headless"
size = "240x150"
[recording]
directory = "$work/sessions"
TOML
# 330 frames at 60 Hz: 5.5 s of the scenario, the default lamp then three switches.
if ! MESA_SHADER_CACHE_DIR="$work/shader-cache" "$replica" --log-level info run --kiosk \
        --config "$work/site.toml" --frames 330 --fast > "$work/run.log" 2>&1; then
    echo "FAIL: the kiosk run failed:" >&2
    cat "$work/run.log" >&2
    exit 1
fi
fail() {
    echo "FAIL: $*" >&2
    grep -E 'render|planner' "$work/run.log" >&2
    exit 1
}
grep -q 'the other 0 compile after it' "$work/run.log" ||
    fail "the kiosk made more than one shading pass for the ColorChecker's lamps"
compiled=$(grep -c 'drew its shading pass for the first time' "$work/run.log")
[ "$compiled" -eq 1 ] || fail "$compiled frames compiled a shading pass (want 1: the first)"
grep -q 'frame [01] drew its shading pass for the first time' "$work/run.log" ||
    fail "the frame that compiled was not the first"
rec=$(ls "$work"/sessions/*.mcap 2>/dev/null | head -1)
[ -n "$rec" ] || fail "the kiosk wrote no session file"
"$replica" inspect "$rec" --json > "$work/inspect.json" 2> "$work/inspect.log" ||
    fail "replica inspect refused $rec: $(cat "$work/inspect.log")"
"$replica" replay "$rec" --json > "$work/replay.json" 2> "$work/replay.log" ||
    fail "replica replay of $rec failed: $(tail -3 "$work/replay.log")"
python3 - "$work/inspect.json" "$work/replay.json" <<'PY' || exit 1
import json, sys
channels = json.load(open(sys.argv[1]))["channels"]
lights = channels["/replica/light"]["count"]
if lights < 4:
    sys.exit(f"FAIL: {lights} light decisions recorded; the default lamp and three switches "
             "make 4")
digests = json.load(open(sys.argv[2]))["display_digests"]
if digests["differing"] != 0 or digests["matched"] != 330:
    sys.exit(f"FAIL: the replay's display digests: {digests} (want 330 matched, 0 differing)")
print(f"PASS: one shading pass for every lamp, compiled by the first frame; {lights} light "
      "decisions recorded; the replay matches all 330 display digests")
PY
