#!/usr/bin/env bash
# Direct-sensor mode and a captured booth as inputs of 'replica run' (issue 33):
#  A. --light direct is recorded in the session's configuration, replays bit for bit, and renders
#     other frames than auto; the kiosk takes it from the site file's [booth] light.
#  B. a booth folder built by 'replica booth build' from a synthetic capture (make_capture.py):
#     run on it with --booth, record, replay bit for bit (the recording names the folder and its
#     digest); replay refuses the booth once its files change; the kiosk takes it from [booth] dir;
#     a site file whose booth folder is missing fails 'replica config check' (exit 1) and the kiosk
#     (exit 78), both naming FILE:LINE: booth.dir.
#   direct_and_booth.sh REPLICA SOURCE_ROOT WORK
set -euo pipefail
replica="$1"
root="$2"
work="$3"
rm -rf "$work" && mkdir -p "$work"
fail() { echo "FAIL: $*" >&2; exit 1; }
frames=30
run=("$replica" --log-level warn run --hal sim --output headless --size 96x60 --rate 10
     --frames "$frames" --fast --no-warm-up --thumbnail-hz 0)
# 'replica inspect --json FILE' -> the recorded configuration's KEY (a dotted path).
recorded() {
    "$replica" inspect --json "$1" | python3 -c '
import json, sys
v = json.load(sys.stdin)["config"]
for k in sys.argv[1].split("."):
    v = v[k]
print(v)' "$2"
}
replays() { # RECORDING DIGESTS [replay options...]: every frame matches, bit for bit
    local rec="$1" digests="$2"
    shift 2
    "$replica" --log-level warn replay "$rec" --no-progress --check "$digests" "$@" \
        > "$rec.replay.txt" 2>&1 || { cat "$rec.replay.txt" >&2; fail "replay of $rec"; }
    grep -q "^check: all $frames frames match" "$rec.replay.txt" ||
        { cat "$rec.replay.txt" >&2; fail "$rec: no $frames-frame match"; }
}

# --- A. Direct-sensor mode forced.
"${run[@]}" --light direct --record "$work/direct.mcap" --digests "$work/direct.json" > /dev/null
"${run[@]}" --record "$work/auto.mcap" --digests "$work/auto.json" > /dev/null
[ "$(recorded "$work/direct.mcap" light)" = direct ] || fail "--light direct not recorded"
[ "$(recorded "$work/auto.mcap" light)" = auto ] || fail "the default light is not recorded as auto"
per_y=$(recorded "$work/direct.mcap" sensing.direct_cdm2_per_y)
python3 -c "import sys; sys.exit(0 if float('$per_y') > 0 else 1)" ||
    fail "direct_cdm2_per_y recorded as $per_y"
replays "$work/direct.mcap" "$work/direct.json"
cmp -s "$work/direct.json" "$work/auto.json" && fail "--light direct rendered the frames of auto"
echo "PASS: --light direct recorded, replayed bit for bit, other frames than auto"

# --- B. A captured booth.
python3 "$root/tests/replay/make_capture.py" "$work/capture"
"$replica" booth build --capture "$work/capture/capture.json" --out "$work/booth" > "$work/build.txt"
grep -q "booth with lights tungsten, d50-fluorescent, d65-fluorescent" "$work/build.txt" ||
    { cat "$work/build.txt" >&2; fail "booth build"; }
"${run[@]}" --booth "$work/booth" --record "$work/booth.mcap" --digests "$work/booth.json" > /dev/null
[ "$(recorded "$work/booth.mcap" booth_dir)" = "$(cd "$work/booth" && pwd -P)" ] ||
    fail "the booth folder is not recorded: $(recorded "$work/booth.mcap" booth_dir)"
digest=$(recorded "$work/booth.mcap" booth_digest)
[ ${#digest} -eq 16 ] || fail "booth_digest '$digest'"
[ "$digest" != "$(recorded "$work/auto.mcap" booth_digest)" ] || fail "the captured booth has the shipped booth's digest"
cmp -s "$work/booth.json" "$work/auto.json" && fail "the captured booth rendered the shipped booth's frames"
# Outside the data folder: replay opens it only under --data-root (as for a scene).
if "$replica" --log-level warn replay "$work/booth.mcap" --no-progress > "$work/noroot.txt" 2>&1; then
    fail "replay opened a booth outside the data folders without --data-root"
fi
grep -q "booth_dir" "$work/noroot.txt" || { cat "$work/noroot.txt" >&2; fail "no booth_dir in the refusal"; }
replays "$work/booth.mcap" "$work/booth.json" --data-root "$work"
# A changed booth is refused, naming the folder and both digests.
python3 "$root/tests/replay/make_capture.py" "$work/capture2" 0.8
"$replica" booth build --capture "$work/capture2/capture.json" --out "$work/booth" > /dev/null
if "$replica" --log-level warn replay "$work/booth.mcap" --no-progress --data-root "$work" \
    > "$work/changed.txt" 2>&1; then
    fail "replay accepted a booth whose files changed"
fi
grep -q "the booth has changed since it was recorded (digest [0-9a-f]*, recorded $digest)" \
    "$work/changed.txt" || { cat "$work/changed.txt" >&2; fail "unclear refusal of a changed booth"; }
echo "PASS: run --booth on a built booth, recorded with its digest, replayed bit for bit; a changed booth refused"

# --- The kiosk from a site file with both keys.
python3 "$root/tests/replay/make_capture.py" "$work/capture" # back to the first capture
"$replica" booth build --capture "$work/capture/capture.json" --out "$work/booth" > /dev/null
mkdir -p "$work/sessions"
"$root/tests/replay/goldens/kiosk-site" "$root/deploy/replica.toml" colorchecker "$work/sessions" |
    sed -e 's/^light = "auto"/light = "direct"/' \
        -e "/^\[booth\]/,/^\[scene\]/ s|^# dir = .*|dir = \"$work/booth\"|" \
    > "$work/kiosk.toml"
grep -q '^light = "direct"' "$work/kiosk.toml" || fail "could not set [booth] light"
grep -q "^dir = \"$work/booth\"" "$work/kiosk.toml" || fail "could not set [booth] dir"
"$replica" config check "$work/kiosk.toml" > "$work/check.txt" 2>&1 ||
    { cat "$work/check.txt" >&2; fail "config check refused the kiosk's site file"; }
"$replica" --log-level warn run --kiosk --config "$work/kiosk.toml" --frames "$frames" --fast --no-planner \
    --no-warm-up --thumbnail-hz 0 --digests "$work/kiosk.json" > /dev/null
files=("$work/sessions"/*.mcap)
[ ${#files[@]} -eq 1 ] || fail "the kiosk wrote ${#files[@]} session files"
[ "$(recorded "${files[0]}" light)" = direct ] || fail "the kiosk did not record [booth] light"
[ "$(recorded "${files[0]}" booth_digest)" = "$digest" ] || fail "the kiosk did not run on [booth] dir"
replays "${files[0]}" "$work/kiosk.json" --data-root "$work"
echo "PASS: the kiosk from [booth] light = \"direct\" and dir, replayed bit for bit"

# --- A site file whose booth folder is missing: config check names FILE:LINE: booth.dir (exit 1,
# as for every problem it finds), and the kiosk refuses the file with exit 78 and the same line.
sed "/^\[booth\]/,/^\[scene\]/ s|^dir = .*|dir = \"$work/no-such-booth\"|" "$work/kiosk.toml" \
    > "$work/missing.toml"
line=$(grep -n "^dir = \"$work/no-such-booth\"" "$work/missing.toml" | cut -d: -f1)
[ -n "$line" ] || fail "could not set a missing [booth] dir"
expected="$work/missing.toml:$line: booth.dir: \"$work/no-such-booth\": no booth.json there"
set +e
"$replica" config check "$work/missing.toml" > "$work/missing.txt" 2>&1
rc=$?
"$replica" run --kiosk --config "$work/missing.toml" --frames 3 > "$work/missing-kiosk.txt" 2>&1
kiosk_rc=$?
set -e
[ "$rc" -eq 1 ] || { cat "$work/missing.txt" >&2; fail "config check exited $rc on a missing booth folder (1 expected)"; }
grep -qF "$expected" "$work/missing.txt" || { cat "$work/missing.txt" >&2; fail "config check: no '$expected'"; }
[ "$kiosk_rc" -eq 78 ] || { cat "$work/missing-kiosk.txt" >&2; fail "the kiosk exited $kiosk_rc on a missing booth folder (78 expected)"; }
grep -qF "$expected" "$work/missing-kiosk.txt" || { cat "$work/missing-kiosk.txt" >&2; fail "kiosk: no '$expected'"; }
echo "PASS: a missing booth folder: config check and the kiosk (exit 78) name $work/missing.toml:$line"
