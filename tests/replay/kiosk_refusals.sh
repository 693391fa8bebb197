#!/usr/bin/env bash
# On the gallery's path ('replica run --kiosk' from a site file), samples the state stage refuses
# are said in the log with why and counted in the run's summary: here every 9th head pose NaN and
# every 3rd spectrum saturated (--inject-faults).
set -euo pipefail
replica="$1"
work="$2"
rm -rf "$work" && mkdir -p "$work/sessions"
fail() { echo "FAIL: $*" >&2; exit 1; }
cat >"$work/site.toml" <<TOML
[run]
hal = "sim"
rate_hz = 30.0
[display]
output = "headless"
size = "32x20"
[recording]
directory = "$work/sessions"
[defaults]
lamp = "d65-fluorescent"
TOML
"$replica" run --kiosk --config "$work/site.toml" --frames 120 --fast \
    --inject-faults nan-pose=9,saturate=3 >/dev/null 2>"$work/run.log" ||
    fail "the kiosk exited $?: $(tail -3 "$work/run.log")"
grep -q "\[state\] \[warning\] tracker: 1 pose not used (the last: a pose that is not finite); the frame keeps the last good eye" "$work/run.log" ||
    fail "no line for the refused pose: $(grep state "$work/run.log")"
grep -q "\[state\] \[warning\] spectrometer: 1 spectrum not used (the last: saturated (a pixel at full scale)" "$work/run.log" ||
    fail "no line for the saturated spectrum: $(grep state "$work/run.log")"
grep -Eq "samples the state stage did not use .*: spectrometer [0-9]+, tracker [0-9]+" "$work/run.log" ||
    fail "the summary does not count them: $(grep -i 'did not use' "$work/run.log")"
echo "ok: refused poses and spectra said and counted on the kiosk path"
