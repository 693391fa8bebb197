#!/usr/bin/env bash
# The running appliance measures its own error (platform/loop/error_probe.h): a --record run with
# --error-probe writes /replica/error_probe messages that 'inspect' lists, its summary reports
# speed and error side by side, and its frames replay bit for bit (the probe changes no frame); a
# kiosk session from the shipped site file (error_probe = 10) holds the channel too; --error-probe
# 0 writes none.
#   error_probe.sh REPLICA SOURCE_ROOT WORK
set -euo pipefail
replica="$1"
root="$2"
work="$3"
rm -rf "$work" && mkdir -p "$work"
fail() { echo "FAIL: $*" >&2; exit 1; }
count() { # messages on /replica/error_probe in an 'inspect' listing
    awk '$1 == "channel" && $3 == "/replica/error_probe" { print $4 }' "$1"
}

# A --record run: probes every 0.5 s of session time, at 160x100.
"$replica" --log-level warn run --hal sim --output headless --frames 40 --rate 10 --size 160x100 \
    --fast --error-probe 0.5 --record "$work/run.mcap" --digests "$work/live.json" --json \
    > "$work/run.json"
probes=$(python3 -c 'import json,sys; print(json.load(open(sys.argv[1]))["error_probe"]["probes"])' "$work/run.json")
[ "$probes" -ge 1 ] || fail "the run's summary reports no probes: $(cat "$work/run.json")"
python3 - "$work/run.json" <<'PY' || fail "the summary's error_probe object is incomplete"
import json, sys
p = json.load(open(sys.argv[1]))["error_probe"]
for k in ("probes", "over_budget", "p95_de00_worst", "max_de00_worst", "cpu_ms_per_probe",
          "cpu_share_of_core", "period_s", "pixels"):
    assert k in p, k
assert 0 <= p["over_budget"] <= p["probes"]
assert p["max_de00_worst"] >= p["p95_de00_worst"] >= 0
assert p["period_s"] == 0.5
PY
"$replica" --log-level warn inspect "$work/run.mcap" > "$work/run.inspect.txt"
n=$(count "$work/run.inspect.txt")
[ -n "$n" ] || fail "inspect lists no /replica/error_probe channel: $(cat "$work/run.inspect.txt")"
[ "$n" -eq "$probes" ] || fail "the recording holds $n probes, the summary says $probes"
# The text summary says it in one line.
"$replica" run --hal sim --output headless --frames 20 --rate 10 --size 160x100 --fast \
    --error-probe 1 2> "$work/text.err" > "$work/text.out" || fail "run failed"
grep -q "speed and error: .* frames over the period; .* probes over the error budget" \
    "$work/text.out" "$work/text.err" || fail "no 'speed and error' line: $(cat "$work/text.err")"
# The probe changes no frame: the recording replays bit for bit.
"$replica" --log-level warn replay "$work/run.mcap" --no-progress --check "$work/live.json" \
    > "$work/replay.txt" 2>&1 || { cat "$work/replay.txt" >&2; fail "the probed run does not replay"; }
grep -q "^check: all 40 frames match" "$work/replay.txt" || fail "no 40-frame match: $(cat "$work/replay.txt")"
# Recorded in the run's configuration.
"$replica" --log-level warn inspect --json "$work/run.mcap" > "$work/run.inspect.json"
grep -q '\\"error_probe_s\\":0.5' "$work/run.inspect.json" ||
    grep -q '"error_probe_s": *0.5' "$work/run.inspect.json" ||
    python3 -c 'import sys; sys.exit(0 if "error_probe_s" in open(sys.argv[1]).read() else 1)' "$work/run.inspect.json" ||
    fail "the session's configuration does not record error_probe_s"

# Off: no messages, no summary object.
"$replica" --log-level warn run --hal sim --output headless --frames 20 --rate 10 --size 160x100 \
    --fast --error-probe 0 --record "$work/off.mcap" --json > "$work/off.json"
python3 -c 'import json,sys; sys.exit("error_probe" in json.load(open(sys.argv[1])))' "$work/off.json" ||
    fail "--error-probe 0 still probed"
"$replica" --log-level warn inspect "$work/off.mcap" > "$work/off.inspect.txt"
[ "$(count "$work/off.inspect.txt")" = "0" ] || fail "--error-probe 0 wrote probes: $(cat "$work/off.inspect.txt")"

# The kiosk from the shipped site file: its session holds the channel.
mkdir -p "$work/sessions"
"$root/tests/replay/goldens/kiosk-site" "$root/deploy/replica.toml" colorchecker "$work/sessions" \
    > "$work/site.toml"
grep -q '^error_probe = 10' "$work/site.toml" || fail "the shipped site file has no error_probe = 10"
"$replica" --log-level warn run --kiosk --config "$work/site.toml" --frames 30 --fast \
    > "$work/kiosk.txt"
files=("$work/sessions"/*.mcap)
[ ${#files[@]} -eq 1 ] || fail "the kiosk wrote ${#files[@]} session files"
"$replica" --log-level warn inspect "${files[0]}" > "$work/kiosk.inspect.txt"
k=$(count "$work/kiosk.inspect.txt")
[ -n "$k" ] && [ "$k" -ge 1 ] || fail "the kiosk session holds no probe: $(cat "$work/kiosk.inspect.txt")"
echo "PASS: $probes probes recorded and replayed bit for bit; kiosk session holds $k; off writes none"
