#!/usr/bin/env bash
# 'replica probe --config FILE': says who it probes as, probes the devices the site file names
# (here none is attached, so each is missing) and says what the kiosk would do with each: start
# without a missing sensor and show the site's defaults meanwhile, open the KMS device or not,
# record into the session folder or not. hal = "sim" opens no sensor. A site file that does not
# exist is refused.
#   probe_config.sh REPLICA SHIPPED_TOML WORK_DIR
set -uo pipefail
replica="$1"
shipped="$2"
work="$3"
rm -rf "$work" && mkdir -p "$work/sessions"
fail() {
    echo "FAIL: $*" >&2
    exit 1
}
site="$work/site.toml"
# The shipped site file, with sessions recorded into a folder this test owns, a KMS device that
# is not there, and the tracker on a port of its own.
sed -e "s|^directory = .*|directory = \"$work/sessions\"|" \
    -e "s|^kms_device = .*|kms_device = \"$work/no-card\"|" \
    -e "s|^port = 4242 |port = 4299 |" "$shipped" >"$site"
out=$("$replica" probe --config "$site" --tracker-wait 0.2 --iio-root "$work/no-iio" 2>"$work/err")
rc=$?
echo "$out"
[ $rc -eq 1 ] || fail "exit $rc with no devices attached, expected 1"
grep -q '^probed as ' <<<"$out" || fail "no 'probed as' line"
if [ "$(id -u)" -ne 0 ] || ! getent passwd replica >/dev/null; then
    grep -Eq "^probed as +(no user 'replica'|probing as .*not as the service's user 'replica')" <<<"$out" ||
        fail "the probe does not say it runs as someone other than the service's user"
fi
grep -q "udp 127.0.0.1:4299\|UDP port 4299" <<<"$out" || fail "the tracker was not probed on the site's port 4299"
expect() {
    grep -q -- "^kiosk *$1" <<<"$out" || fail "no kiosk line '$1'"
}
expect "spectrometer: missing: the kiosk starts without it, tries it again every second and meanwhile shows the lamp 'd65-fluorescent' (defaults.lamp)"
expect "tracker: missing: .*the view from defaults.eye_m"
expect "accelerometer: missing: .*the tilt defaults.tilt_deg"
expect "lamp selector: none configured"
expect "display $work/no-card: cannot open it: No such file or directory"
expect "sessions $work/sessions: can write"

# The JSON report carries the same.
"$replica" probe --config "$site" --tracker-wait 0.2 --iio-root "$work/no-iio" --json \
    >"$work/report.json" 2>/dev/null
python3 - "$work/report.json" <<'PY' || fail "the JSON report lacks probed_as or kiosk"
import json, sys
r = json.load(open(sys.argv[1]))
assert set(r["probed_as"]) >= {"user", "groups", "service_user"}, r["probed_as"]
assert any(line.startswith("spectrometer: missing") for line in r["kiosk"]), r["kiosk"]
PY

# hal = "sim": the kiosk opens no sensor.
sed -e 's|^hal = .*|hal = "sim"|' "$site" >"$work/sim.toml"
sim=$("$replica" probe --config "$work/sim.toml" --tracker-wait 0.2 --iio-root "$work/no-iio" 2>/dev/null)
grep -q '^kiosk *hal = "sim": the kiosk opens no sensor' <<<"$sim" || fail "hal = sim: no 'opens no sensor' line"

# A missing site file: refused by name.
if "$replica" probe --config "$work/absent.toml" >/dev/null 2>"$work/err"; then
    fail "a missing site file was accepted"
fi
grep -q "absent.toml" "$work/err" || fail "the missing site file is not named: $(cat "$work/err")"
echo "ok"
