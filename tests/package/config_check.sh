#!/usr/bin/env bash
# 'replica config check': the shipped site file passes; a file with one mistake of each kind is
# refused with one line per mistake naming the file, the line and the key; 'replica run' refuses
# it too (exit 78, which the unit does not restart on), and the command line overrides the file.
#   config_check.sh REPLICA SHIPPED_TOML WORK_DIR
set -uo pipefail
replica="$1"
shipped="$2"
work="$3"
rm -rf "$work" && mkdir -p "$work"
fail() {
    echo "FAIL: $*" >&2
    exit 1
}
# The shipped file as shipped says hal = "live" on the synthetic display profile, which the kiosk
# refuses until the panel's own profile is set: the check (which resolves what the kiosk resolves)
# says so in one line naming the key; allowed, it checks.
out=$("$replica" config check "$shipped" 2>&1)
status=$?
[ $status -eq 1 ] || fail "the shipped site file: exit $status, expected 1 (the synthetic profile)"
grep -q "^$shipped:[0-9]*: display.allow_synthetic: the kiosk refuses a live run" <<<"$out" ||
    fail "the shipped site file: $out"
sed 's/^allow_synthetic = false/allow_synthetic = true/' "$shipped" >"$work/allowed.toml"
"$replica" config check "$work/allowed.toml" || fail "the shipped site file allowing it does not check"

# The calibrations write into the shipped file what it then takes: the stand's and the tracker's
# sections (with their figures for people) still check, and a stand taped in centimetres is
# refused with the file unchanged, as is a section whose key the reader would refuse.
python3 - "$work" <<'PY'
import math, sys
work = sys.argv[1]
g, L = 9.80665, 0.035 + 0.324
with open(f"{work}/tilts.csv", "w") as f, open(f"{work}/tilts_cm.csv", "w") as cm:
    for deg in (0.0, 20.0, 40.0):
        a = math.radians(deg)
        y, z = 0.18 + L * math.cos(a), -0.07 - L * math.sin(a)
        f.write(f"0.0,{g*math.cos(a):.6f},{g*math.sin(a):.6f},{y:.6f},{z:.6f}\n")
        cm.write(f"0.0,{g*math.cos(a):.6f},{g*math.sin(a):.6f},{100*y:.4f},{100*z:.4f}\n")
with open(f"{work}/marker.csv", "w") as f:
    for q in ([0.0, 0.3, 0.5], [0.2, 0.5, 0.6], [-0.2, 0.6, 0.7], [0.1, 0.2, 0.9]):
        t = [q[0] - 0.1, q[1] - 0.42, q[2] + 0.05]  # the tracker 0.1 m along x, no rotation
        f.write(",".join(f"{v:.6f}" for v in q + t) + "\n")
PY
calibrated="$work/calibrated.toml"
cp "$work/allowed.toml" "$calibrated"
"$replica" calibrate stand --points "$work/tilts.csv" --site "$calibrated" --panel-width 0.518 \
    --panel-height 0.324 >/dev/null 2>"$work/stand.log" || fail "calibrate stand: $(cat "$work/stand.log")"
"$replica" calibrate tracker --points "$work/marker.csv" --site "$calibrated" \
    >/dev/null 2>"$work/tracker.log" || fail "calibrate tracker: $(cat "$work/tracker.log")"
grep -q "^hinge_axis_panel = " "$calibrated" && grep -q "^T_booth_tracker = " "$calibrated" ||
    fail "the calibrations did not write their sections"
out=$("$replica" config check "$calibrated" 2>&1) || fail "the calibrated site file: $out"
cp "$calibrated" "$work/before_cm.toml"
out=$("$replica" calibrate stand --points "$work/tilts_cm.csv" --site "$calibrated" \
    --panel-width 0.518 --panel-height 0.324 2>&1) && fail "a stand taped in centimetres was written"
grep -q "give top_y and top_z in metres" <<<"$out" || fail "the centimetre stand: $out"
cmp -s "$calibrated" "$work/before_cm.toml" || fail "the centimetre stand changed the site file"

bad="$work/bad.toml"
cat >"$bad" <<'TOML'
[display]
size = 1920
allow_synthetic = "yes"
[stand]
panel_width_m = -0.5
hinge_m = [0.0, nan, 0.1]
[tracker]
port = 70000
[run]
hal = "simulated"
rate_hz = inf
[recording]
rotate_secs = 60
[colour]
x = 1
TOML
out=$("$replica" config check "$bad" 2>&1)
status=$?
[ $status -eq 1 ] || fail "exit $status for a bad file, expected 1"
expect() {
    grep -qF -- "$1" <<<"$out" || fail "no line '$1' in:
$out"
}
expect "$bad:2: display.size: expected a string, got an integer"
expect "$bad:3: display.allow_synthetic: expected true or false, got a string"
expect "$bad:5: stand.panel_width_m: -0.5 is out of range"
expect "$bad:6: stand.hinge_m: not a finite number"
expect "$bad:8: tracker.port: 70000 is out of range [1, 65535]"
expect "$bad:10: run.hal: 'simulated' is not one of: live, replay, sim"
expect "$bad:11: run.rate_hz: not a finite number"
expect "$bad:13: recording.rotate_secs: unknown key"
expect "$bad:14: colour: unknown section or key"
expect "$bad: 9 problems"

printf '[display]\nsize = "1920x"\n[scene\n' >"$work/syntax.toml"
out=$("$replica" config check "$work/syntax.toml" 2>&1) && fail "a syntax error passed"
grep -q "^$work/syntax.toml:3: not valid TOML" <<<"$out" || fail "syntax error: $out"
out=$("$replica" config check "$work/missing.toml" 2>&1) && fail "a missing file passed"

"$replica" run --config "$bad" --frames 1 --fast >/dev/null 2>&1
status=$?
[ $status -eq 78 ] || fail "run on a bad site file: exit $status, expected 78"

# The shipped file says hal = "live" on the synthetic profile: the kiosk refuses it (78) after a
# loud warning, before opening any device.
out=$("$replica" run --kiosk --config "$shipped" --output headless --frames 1 2>&1)
status=$?
[ $status -eq 78 ] || fail "kiosk on the synthetic profile: exit $status, expected 78"
grep -q "LIVE RUN ON A SYNTHETIC DISPLAY PROFILE" <<<"$out" || fail "no loud warning: $out"
grep -q "allow_synthetic = true" <<<"$out" || fail "the refusal does not say how: $out"

# A good file: hal sim from the file, the frame count from the command line, and the resolved
# configuration (with the site's geometry) recorded in the session.
good="$work/good.toml"
cat >"$good" <<TOML
[run]
hal = "sim"
rate_hz = 30.0
[display]
output = "headless"
size = "64x40"
profile = "displays/wide-ips-synthetic.json"
[stand]
panel_width_m = 0.6
[defaults]
lamp = "tungsten"
TOML
"$replica" config check "$good" || fail "good file refused"
# A sessions folder the kiosk could never make (it would run without recording) fails the check,
# naming the line and the key; the kiosk itself runs on, as it does with a full disk.
cp "$good" "$work/proc.toml"
printf '[recording]\ndirectory = "/proc/replica-sessions"\n' >>"$work/proc.toml"
out=$("$replica" config check "$work/proc.toml" 2>&1) && fail "a sessions folder under /proc passed"
grep -q "^$work/proc.toml:13: recording.directory: '/proc/replica-sessions' cannot hold the sessions" <<<"$out" ||
    fail "sessions folder under /proc: $out"
"$replica" run --config "$good" --frames 3 --fast --size 48x30 --record "$work/s.mcap" \
    >"$work/run.log" 2>&1 || fail "run --config failed: $(tail -3 "$work/run.log")"
"$replica" inspect "$work/s.mcap" --json >"$work/inspect.json" || fail "inspect failed"
python3 - "$work/inspect.json" <<'PY' || fail "the recorded configuration is wrong"
import json, sys
j = json.load(open(sys.argv[1]))
def find(o, key):
    if isinstance(o, dict):
        if key in o:
            return o[key]
        for v in o.values():
            r = find(v, key)
            if r is not None:
                return r
    return None
cfg = j["config"]
assert "(git " in j["software"], j["software"]
assert cfg["width"] == 48 and cfg["height"] == 30, (cfg["width"], cfg["height"])  # command line wins
assert cfg["rate_hz"] == 30.0, cfg["rate_hz"]                                     # from the file
assert cfg["panel_width_m"] == 0.6 and cfg["panel_height_m"] == 0.324
assert cfg["default_lamp"] == "tungsten"
assert cfg["display"] == "displays/wide-ips-synthetic.json", cfg["display"]  # portable: data-relative
assert cfg["run_options"]["hal"] == "sim"
assert cfg["site"]["source"].endswith("good.toml")
print("recorded:", cfg["width"], cfg["height"], cfg["rate_hz"], cfg["panel_width_m"])
PY
# run.hal = "replay": the display fed by a committed recording (what the VM boot test shows),
# frame for frame the same on every run.
sample="$(dirname "$shipped")/../recordings/samples/walk-v1.mcap"
cat >"$work/replay.toml" <<TOML
[run]
hal = "replay"
replay_file = "$sample"
[display]
output = "headless"
size = "32x20"
TOML
for i in 1 2; do
    "$replica" --log-level warn run --config "$work/replay.toml" --frames 20 --fast \
        --digests "$work/replay$i.json" >/dev/null || fail "run on hal = replay failed"
done
cmp -s "$work/replay1.json" "$work/replay2.json" || fail "hal = replay is not deterministic"
echo "ok"
