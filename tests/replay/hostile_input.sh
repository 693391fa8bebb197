#!/usr/bin/env bash
# Hostile and careless input over every command and file the CLI reads (issue 22): wrong JSON
# types, out-of-range and non-finite numbers, directories, FIFOs, devices and symbolic link loops
# where a file is expected, names that would leave the output folder, recordings that lie about
# their sizes or hold decompression bombs, name files outside the data folder, carry impossible
# frames or terminal escapes. Each case must end with its own exit code and exactly one line that
# says what is wrong (and names the file or JSON path), never an abort, a hang or memory exhaustion:
# every command runs under a virtual memory limit (ulimit -v, except under ASan, which reserves
# terabytes of address space) and a hang guard.
#   hostile_input.sh REPLICA SOURCE_DIR WORK
set -uo pipefail
replica="$1"
data="$2/data"
sample="$2/recordings/samples/walk-v3.mcap"
work="$3"
here="$(cd "$(dirname "$0")" && pwd)"
rm -rf "$work" && mkdir -p "$work"
limit_kb=2000000 # 2 GB of address space: a decompression bomb or a 30 M count spectrum would need more
# ldd's output is read whole before matching: `ldd | grep -q` under pipefail races (grep exits at
# the first match, ldd dies of SIGPIPE, the pipeline fails and ASan went undetected in CI).
libs=$(ldd "$replica" 2>/dev/null || true)
if [[ "$libs" == *libasan* ]]; then
    limit_kb=unlimited
fi
pass=0
status=0
fail() {
    echo "FAIL: $*" >&2
    status=1
}

# expect CODE PATTERN [env VAR=...] -- replica ARGS...: exit CODE, one stderr line matching PATTERN.
expect() {
    local code="$1" pattern="$2"
    shift 2
    local envs=()
    while [ "$1" != "--" ]; do
        envs+=("$1")
        shift
    done
    shift
    local err got lines
    err=$( (ulimit -v "$limit_kb"; env "${envs[@]}" timeout 60 "$replica" "$@") 2>&1 >/dev/null)
    got=$?
    lines=$(printf '%s\n' "$err" | grep -c .)
    if [ "$got" -eq 124 ]; then
        fail "replica $* hung (killed after 60 s)"
    elif [ "$got" -ne "$code" ]; then
        fail "replica $* exited $got, expected $code: $err"
    elif [ "$lines" -ne 1 ]; then
        fail "replica $* printed $lines lines, expected one: $err"
    elif ! grep -qE -- "$pattern" <<<"$err"; then
        fail "replica $* did not say /$pattern/: $err"
    else
        pass=$((pass + 1))
        echo "ok: exit $got: $err"
    fi
}

R=("--log-level" "error")

# --- The command line: numbers, levels, paths.
expect 2 "--frames.*not in range" -- "${R[@]}" run --frames -1
expect 2 "--frames.*not in range" -- "${R[@]}" run --frames 4294967296
expect 2 "--rate.*'nan' is not a finite number" -- "${R[@]}" run --rate nan
expect 2 "--rate.*(not a finite number|not in range)" -- "${R[@]}" run --rate inf
expect 2 "--size 16384x1" -- "${R[@]}" run --size 16384x1 --frames 1
expect 2 "--specular-lod-bias.*not a finite number" -- "${R[@]}" render --scene "$data/scenes/metamer" \
    --light d65 --out "$work/x.exr" --specular-lod-bias nan
expect 2 "--lux.*not a finite number" -- "${R[@]}" display study --lux nan
expect 2 "--tracker-wait.*not a finite number" -- "${R[@]}" probe --tracker-wait nan
expect 2 "unknown log level 'bogus'.*trace, debug, info" -- --log-level bogus inspect "$sample"
expect 2 "REPLICA_LOG.*unknown log level 'loud'" REPLICA_LOG=loud -- inspect "$sample"
expect 2 "--check.*empty name" -- "${R[@]}" replay "$sample" --check ""
expect 2 "must end in .exr" -- "${R[@]}" render --scene "$data/scenes/metamer" --light d65 --out "$work/x.png"
# --log-level after the subcommand works like before it.
out=$("$replica" inspect "$sample" --log-level error 2>&1 >/dev/null)
[ $? -eq 0 ] && [ -z "$out" ] || fail "--log-level after the subcommand: $out"
# The command line wins over $REPLICA_LOG: error on the line, debug in the environment, no debug.
out=$(REPLICA_LOG=debug "$replica" --log-level error inspect "$sample" 2>&1 >/dev/null)
[ -z "$out" ] || fail "REPLICA_LOG beat --log-level: $out"

# --- Recordings are written without following links and never over an existing one.
printf 'evidence' > "$work/existing.mcap"
expect 2 "already exists; pass --force" -- "${R[@]}" run --frames 1 --record "$work/existing.mcap"
[ "$(cat "$work/existing.mcap")" = evidence ] || fail "run --record truncated an existing recording"
ln -s "$work/target" "$work/link.mcap"
expect 2 "symbolic link" -- "${R[@]}" run --frames 1 --record "$work/link.mcap"
[ ! -e "$work/target" ] || fail "run --record wrote through a symbolic link"

# --- Scene JSON: wrong types and out-of-range values name the JSON path.
scene() { # NAME PYTHON-EXPRESSION-ON-j
    rm -rf "$work/$1" && cp -r "$data/scenes/metamer" "$work/$1"
    python3 - "$work/$1/scene.json" "$2" <<'PY'
import json, sys
path, change = sys.argv[1], sys.argv[2]
j = json.load(open(path))
exec(change)
json.dump(j, open(path, "w"))
PY
}
scene name5 'j["name"] = 5'
expect 1 "scene.json: /name: expected a string, found an integer" -- "${R[@]}" render --scene "$work/name5" --light d65 --out "$work/x.exr"
scene wardx 'j["ward"] = "x"'
expect 1 "scene.json: /ward: expected an object, found a string" -- "${R[@]}" render --scene "$work/wardx" --light d65 --out "$work/x.exr"
scene alphanull 'j["ward"]["alpha"] = None'
expect 1 "scene.json: /ward/alpha: expected a number in \[0, 5\], found null" -- "${R[@]}" render --scene "$work/alphanull" --light d65 --out "$work/x.exr"
scene huge 'j["size_m"][0] = 1e308'
expect 1 "scene.json: /size_m/0: expected a number in" -- "${R[@]}" render --scene "$work/huge" --light d65 --out "$work/x.exr"
scene refl 'j["palette"][0]["reflectance"][3] = "0.5"'
expect 1 "scene.json: /palette/0/reflectance/3: expected a number" -- "${R[@]}" render --scene "$work/refl" --light d65 --out "$work/x.exr"
# Directories, FIFOs, devices and link loops where scene.json should be.
mkdir -p "$work/dir" && cp -r "$data/scenes/metamer/." "$work/dir/" && rm "$work/dir/scene.json" && mkdir "$work/dir/scene.json"
expect 1 "scene.json: is a directory" -- "${R[@]}" render --scene "$work/dir" --light d65 --out "$work/x.exr"
mkdir -p "$work/fifo" && cp -r "$data/scenes/metamer/." "$work/fifo/" && rm "$work/fifo/scene.json" && mkfifo "$work/fifo/scene.json"
expect 1 "scene.json: is a FIFO" -- "${R[@]}" render --scene "$work/fifo" --light d65 --out "$work/x.exr"
mkdir -p "$work/zero" && ln -s /dev/zero "$work/zero/scene.json"
expect 1 "scene.json: is a device" -- "${R[@]}" render --scene "$work/zero" --light d65 --out "$work/x.exr"
mkdir -p "$work/loop" && ln -s "$work/loop/b" "$work/loop/a" && ln -s "$work/loop/a" "$work/loop/b" && ln -s a "$work/loop/scene.json"
expect 1 "symbolic link loop" -- "${R[@]}" render --scene "$work/loop" --light d65 --out "$work/x.exr"
ln -s "$work/sceneloop" "$work/sceneloop" 2>/dev/null
expect 2 "--scene .*no scene.json" -- "${R[@]}" run --frames 1 --scene "$work/sceneloop"

# --- Booth JSON.
booth() {
    rm -rf "$work/$1" && cp -r "$data/booth" "$work/$1"
    python3 - "$work/$1/booth.json" "$2" <<'PY'
import json, sys
path, change = sys.argv[1], sys.argv[2]
j = json.load(open(path))
exec(change)
json.dump(j, open(path, "w"))
PY
}
booth escape 'j["lights"][0]["luminance"] = "../../../etc/hostname"'
expect 1 "lights\[0\].luminance: '../../../etc/hostname' cannot name a file" -- "${R[@]}" render --booth "$work/escape" --scene "$data/scenes/metamer" --light d65 --out "$work/x.exr"
booth far 'j["lights"][0]["centre"][0] = 1e308'
expect 1 "booth.json: /lights/0/centre/0: expected a number in \[-100, 100\]" -- "${R[@]}" render --booth "$work/far" --scene "$data/scenes/metamer" --light d65 --out "$work/x.exr"
booth dark 'j["lights"][0]["spd"] = [-1.0] * 36'
expect 1 "lights\[0\]: spd has no positive power" -- "${R[@]}" render --booth "$work/dark" --scene "$data/scenes/metamer" --light d65 --out "$work/x.exr"

# --- Capture JSON for 'booth build': names that would leave --out, impossible texel counts.
capture() { # NAME NAME-OF-LIGHT TEXELS
    cat > "$work/$1.json" <<JSON
{"lights": [{"name": "$2", "spd_column": "A", "centre": [0, 1.5, 0], "edge_u": [0.5, 0, 0],
  "edge_v": [0, 0, 0.5], "texels": $3, "corners": [[0, 0], [10, 0], [10, 10], [0, 10]],
  "exposures": [{"file": "e.png", "seconds": 0.01}], "calibration": {"cdm2_per_unit": 1}}]}
JSON
}
capture escaped "../../escaped" "[8, 8]"
expect 1 "lights\[0\].name: '../../escaped' cannot name a file" -- "${R[@]}" booth build --capture "$work/escaped.json" --out "$work/out/booth"
[ ! -e "$work/escaped.exr" ] && [ ! -e "$work/out/escaped.exr" ] || fail "booth build wrote outside --out"
capture texels-huge ok "[100000, 100000]"
expect 1 "/lights/0/texels/0: expected an integer in \[1, 4096\]" -- "${R[@]}" booth build --capture "$work/texels-huge.json" --out "$work/out/booth"
capture texels-negative ok "[-1, 5]"
expect 1 "/lights/0/texels/0: expected an integer in \[1, 4096\]" -- "${R[@]}" booth build --capture "$work/texels-negative.json" --out "$work/out/booth"
expect 1 "/dev/zero: is a device" -- "${R[@]}" booth build --capture /dev/zero --out "$work/out/booth"
expect 1 "is a directory" -- "${R[@]}" booth build --capture "$work" --out "$work/out/booth"

# --- Display profiles: devices, /proc, wrong types.
expect 1 "/dev/zero: is a device" -- "${R[@]}" run --frames 1 --display-profile /dev/zero
expect 1 "/proc/self/mem: cannot read display profile" -- "${R[@]}" run --frames 1 --display-profile /proc/self/mem
python3 - "$data/displays/wide-ips-synthetic.json" "$work/profile-type.json" <<'PY'
import json, sys
j = json.load(open(sys.argv[1]))
j["bit_depth"] = "eight"
json.dump(j, open(sys.argv[2], "w"))
PY
expect 1 "profile-type.json: /bit_depth: expected an integer" -- "${R[@]}" display forward "$work/profile-type.json" --rgb 1,2,3

# --- Files read once through the bounded reader (issue 32): 'color de2000' checked its pairs and
# then opened them again (a FIFO swapped in between hung it); now one open, no wait, a size.
mkfifo "$work/pairs-fifo.csv"
expect 1 "pairs-fifo.csv: is a FIFO, not a CSV file" -- "${R[@]}" color de2000 "$work/pairs-fifo.csv"
expect 1 "/dev/zero: is a device, not a CSV file" -- "${R[@]}" color de2000 /dev/zero
expect 1 "is a directory, not a CSV file" -- "${R[@]}" color de2000 "$work"
expect 1 "nope.csv: cannot open \(does the file exist\?\)" -- "${R[@]}" color de2000 "$work/nope.csv"

# --- Errors that printed nothing on standard error, or one error several times (found by
# running every command with bad inputs; the count is in docs/recordings.md).
# probe's report goes to standard output; a failing probe also says so in one line.
expect 1 "probe: .*missing or not working" -- "${R[@]}" probe --iio-root "$work/no-iio" --tracker-wait 0.2
expect 1 "probe: .*missing or not working" -- "${R[@]}" probe --json --iio-root "$work/no-iio" --tracker-wait 0.2
# display flare sets up the study twice; a bad profile or basis is said once.
expect 1 "is a directory, not a display profile" -- "${R[@]}" display flare "$work"
expect 1 "nope.csv: cannot open spectral table" -- "${R[@]}" display flare --basis nope

# --- Recordings from the field.
python3 "$here/craft_recordings.py" "$work/rec" || fail "craft_recordings.py failed"
rec="$work/rec"
for cmd in inspect replay; do
    expect 1 "claims 268435456 uncompressed bytes \(at most 16 MiB\)" -- "${R[@]}" $cmd "$rec/claims-4x256mib.mcap"
    expect 1 "claims 268435456 uncompressed bytes" -- "${R[@]}" $cmd "$rec/claims-200x256mib.mcap"
    expect 1 "its zstd frame holds 16" -- "${R[@]}" $cmd "$rec/claims-more-than-frame.mcap"
    expect 1 "decompresses to more than 64 MiB" -- "${R[@]}" $cmd "$rec/bomb-40x16mib.mcap"
    expect 1 "/dev/zero: is a device" -- "${R[@]}" $cmd /dev/zero
    expect 1 "is a directory" -- "${R[@]}" $cmd "$rec"
done
if [ -f "$rec/messages-40x16mib.mcap" ]; then # written where the zstd program exists
    for cmd in inspect replay; do
        expect 1 "decompresses to more than 64 MiB" -- "${R[@]}" $cmd "$rec/messages-40x16mib.mcap"
    done
fi
expect 1 "recover" -- "${R[@]}" recover "$rec/bomb-40x16mib.mcap" "$work/recovered.mcap"
# recover writes a new file beside OUT and renames it into place: an existing OUT is replaced only
# with --force, a symbolic link is never followed or replaced, the input is never written.
cp "$sample" "$work/rec-in.mcap"
sum_in=$(sha256sum < "$work/rec-in.mcap")
printf 'keep me' > "$work/rec-out.mcap"
expect 1 "rec-out.mcap: already exists; pass --force" -- "${R[@]}" recover "$work/rec-in.mcap" "$work/rec-out.mcap"
[ "$(cat "$work/rec-out.mcap")" = "keep me" ] || fail "recover without --force changed an existing OUT"
out=$("$replica" "${R[@]}" recover --force "$work/rec-in.mcap" "$work/rec-out.mcap" 2>&1 >/dev/null)
code=$?
if [ "$code" -ne 0 ] || [ -n "$out" ] || ! "$replica" "${R[@]}" inspect "$work/rec-out.mcap" >/dev/null; then
    fail "recover --force over an existing file: exit $code: $out"
else
    pass=$((pass + 1))
    echo "ok: recover --force replaces an existing OUT with a sound recording"
fi
ln -s "$work/rec-target.mcap" "$work/rec-link.mcap"
expect 1 "rec-link.mcap: is a symbolic link" -- "${R[@]}" recover --force "$work/rec-in.mcap" "$work/rec-link.mcap"
[ ! -e "$work/rec-target.mcap" ] || fail "recover wrote through a symbolic link"
expect 1 "rec-in.mcap: is the input itself" -- "${R[@]}" recover --force "$work/rec-in.mcap" "$work/rec-in.mcap"
ln "$work/rec-in.mcap" "$work/rec-hardlink.mcap"
expect 1 "rec-hardlink.mcap: is the input itself" -- "${R[@]}" recover --force "$work/rec-in.mcap" "$work/rec-hardlink.mcap"
mkdir -p "$work/rec-dir.mcap"
expect 1 "rec-dir.mcap: exists and is not a regular file" -- "${R[@]}" recover --force "$work/rec-in.mcap" "$work/rec-dir.mcap"
mkfifo "$work/rec-fifo.mcap"
expect 1 "rec-fifo.mcap: exists and is not a regular file" -- "${R[@]}" recover --force "$work/rec-in.mcap" "$work/rec-fifo.mcap"
expect 1 "the folder .*/nowhere does not exist" -- "${R[@]}" recover "$work/rec-in.mcap" "$work/nowhere/out.mcap"
[ "$(sha256sum < "$work/rec-in.mcap")" = "$sum_in" ] || fail "recover changed its input"
leftover=$(find "$work" -maxdepth 1 -name '.*.recover-*')
[ -z "$leftover" ] || fail "recover left temporary files: $leftover"
# The session message and the run configuration are held against their written schemas
# (recordings/session_schema.cpp, platform/run_config_schema.cpp): the JSON path is named.
expect 1 "run configuration: /width: expected an integer in \[1, 8192\], found 16384" -- "${R[@]}" replay "$rec/frame-16384x1.mcap"
expect 1 "run configuration: /rate_hz: expected a number in \[1, 1000\], found 0.0" -- "${R[@]}" replay "$rec/rate-nan.mcap"
expect 1 "run configuration: /lights_u: expected an integer in \[1, 256\], found 65536" -- "${R[@]}" replay "$rec/lights-overflow.mcap"
expect 1 "/replica/session message: /format_version: expected an integer in \[0, 65535\], found a string" -- "${R[@]}" replay "$rec/session-format-string.mcap"
expect 1 "/replica/session message: /config: expected a string, found an object" -- "${R[@]}" replay "$rec/session-config-object.mcap"
expect 1 "/replica/session message: /wall_clock_start_ns: expected an integer in \[0, .*\], found -5" -- "${R[@]}" replay "$rec/session-clock-negative.mcap"
expect 1 "/replica/session message: /tracker/model: expected a string, found an integer" -- "${R[@]}" replay "$rec/session-device-number.mcap"
expect 1 "run configuration: /rate_hz: expected a number in \[1, 1000\], found 1e\+308" -- "${R[@]}" replay "$rec/config-rate-1e308.mcap"
expect 1 "run configuration: .*number overflow parsing '1e999'" -- "${R[@]}" replay "$rec/config-rate-inf.mcap"
expect 1 "run configuration: /width: expected an integer in \[1, 8192\], found a string" -- "${R[@]}" replay "$rec/config-width-string.mcap"
expect 1 "run configuration: /width: required but missing" -- "${R[@]}" replay "$rec/config-width-missing.mcap"
expect 1 "run configuration: /t_booth_tracker/rotation: expected an array of 9 items, found 8" -- "${R[@]}" replay "$rec/config-rotation-8.mcap"
expect 1 "run configuration: /specular_lod_bias: expected a number in \[-8, 8\], found null" -- "${R[@]}" replay "$rec/config-lod-bias-null.mcap"
expect 1 "run configuration: .*parse error" -- "${R[@]}" replay "$rec/config-not-json.mcap"
# Unknown keys are warned (one line naming the recording and the key) and the replay goes on.
expect 0 "session-unknown-key.mcap: /replica/session message: /owner: unknown key, ignored" -- --log-level warn replay "$rec/session-unknown-key.mcap"
expect 0 "config-unknown-key.mcap: run configuration: /exposure_hack: unknown key, ignored" -- --log-level warn replay "$rec/config-unknown-key.mcap"
expect 1 "display is '/etc/shadow', outside the data folders" -- "${R[@]}" replay "$rec/profile-etc-shadow.mcap"
expect 1 "spectrometer_calibration '../../../../etc/passwd' is not a name inside" -- "${R[@]}" replay "$rec/calibration-dotdot.mcap"
expect 1 "scene_dir is '/tmp', outside the data folders" -- "${R[@]}" replay "$rec/scene-elsewhere.mcap"
expect 1 "no digest of its scene.*--allow-undigested" -- "${R[@]}" replay "$rec/scene-undigested.mcap"
expect 1 "frame 1 has tick_ns 10000000, before 20000000" -- "${R[@]}" replay "$rec/tick-backwards.mcap"
expect 1 "20000 counts; a spectrometer has at most 16384 pixels" -- "${R[@]}" replay "$rec/spectrum-20000-counts.mcap"
expect 1 "message \(sequence 0\) of 20971[0-9]+ bytes" -- "${R[@]}" replay "$rec/message-2mib.mcap"
# A tick 285 years away: --clock recorded waits at most a second for a frame, then ends.
out=$( (ulimit -v "$limit_kb"; timeout 120 "$replica" "${R[@]}" replay "$rec/tick-285-years.mcap" \
    --clock recorded) 2>&1 >/dev/null)
code=$?
if [ "$code" -ne 0 ]; then
    fail "replay --clock recorded of a tick 285 years away exited $code (124: hung): $out"
else
    pass=$((pass + 1))
    echo "ok: replay --clock recorded of a tick 285 years away ends"
fi
# --- Issue 32: limits at every parser, each case under ulimit -v with its time and peak memory
# printed (bounded: exits by the 60 s hang guard; peak resident memory asserted).
# bounded MAX_RSS_MB CODE PATTERN -- replica ARGS...: as expect, plus peak RSS (from /usr/bin/time).
bounded() {
    local max_mb="$1" code="$2" pattern="$3"
    shift 4
    local err got lines stats
    err=$( (ulimit -v "$limit_kb"; /usr/bin/time -f "time %e s, peak %M KB" -o "$work/time.txt" \
        timeout 60 "$replica" "$@") 2>&1 >/dev/null)
    got=$?
    stats=$(cat "$work/time.txt" 2>/dev/null | tail -1)
    lines=$(printf '%s\n' "$err" | grep -c .)
    local kb
    kb=$(printf '%s' "$stats" | sed -E 's/.*peak ([0-9]+) KB.*/\1/')
    if [ "$got" -eq 124 ]; then
        fail "replica $* hung (killed after 60 s)"
    elif [ "$got" -ne "$code" ]; then
        fail "replica $* exited $got, expected $code: $err"
    elif [ "$lines" -ne 1 ]; then
        fail "replica $* printed $lines lines, expected one: $err"
    elif ! grep -qE -- "$pattern" <<<"$err"; then
        fail "replica $* did not say /$pattern/: $err"
    elif [ "$limit_kb" != unlimited ] && [ -n "$kb" ] && [ "$kb" -gt $((max_mb * 1024)) ]; then
        fail "replica $* peaked at $kb KB, more than $max_mb MB"
    else
        pass=$((pass + 1))
        echo "ok: exit $got ($stats): $err"
    fi
}
if [ -x /usr/bin/time ]; then
    for cmd in inspect replay; do
        bounded 200 1 "run configuration: JSON nested 100001 levels deep, more than the limit of 32" -- "${R[@]}" $cmd "$rec/config-deep.mcap"
        bounded 200 1 "/replica/session message \(sequence 0\): JSON nested 201 levels deep" -- "${R[@]}" $cmd "$rec/session-deep.mcap"
        bounded 200 1 "2 channels carry /replica/session \(ids 1 and 8\)" -- "${R[@]}" $cmd "$rec/session-twice.mcap"
    done
    bounded 200 1 "config-deep.mcap: run configuration: JSON nested 100001" -- "${R[@]}" inspect --json "$rec/config-deep.mcap"
    bounded 200 1 "Chunk Index at byte [0-9]+ points at bytes 9223372036854775808" -- "${R[@]}" inspect "$rec/index-2pow63.mcap"
    bounded 200 1 "Chunk Index at byte [0-9]+ points at bytes 50\.\." -- "${R[@]}" inspect "$rec/index-off-by-one.mcap"
    # Recover on 16 MiB of nested chunks: linear (143 s before), nothing recoverable.
    bounded 400 1 "nested-zero-16mib.mcap: nothing recoverable" -- "${R[@]}" recover "$rec/nested-zero-16mib.mcap" "$work/nested-out.mcap"
    bounded 400 1 "nested-crc-16mib.mcap: nothing recoverable" -- "${R[@]}" recover "$rec/nested-crc-16mib.mcap" "$work/nested-out.mcap"
    # recover streams: a crashed 20 MiB session (no Data End, summary or footer) recovers within
    # 64 MB whatever its size (before: the file and every message held, about 13 MB + 4 x the file:
    # 93 MB here, 413 MB for 100 MiB). It is one golden's body 64 times over, so each repeat's
    # session message and its frames going back in time fail the reader's checks: exit 3 (dropped),
    # where recover used to copy them into a file that inspect and replay refuse.
    python3 "$2/tests/benchmarks/crashed_recording.py" "$2/tests/replay/goldens/kiosk-painting.mcap" \
        "$work/crashed-20mib.mcap" 64
    err=$( (ulimit -v "$limit_kb"; /usr/bin/time -f "time %e s, peak %M KB" -o "$work/time.txt" \
        timeout 60 "$replica" "${R[@]}" recover "$work/crashed-20mib.mcap" "$work/crashed-out.mcap") 2>&1 >/dev/null)
    got=$?
    stats=$(tail -1 "$work/time.txt")
    kb=$(printf '%s' "$stats" | sed -E 's/.*peak ([0-9]+) KB.*/\1/')
    if [ "$got" -ne 3 ] || [ -n "$err" ]; then
        fail "recover of a crashed 20 MiB session: exit $got (expected 3): $err"
    elif [ "$limit_kb" != unlimited ] && [ "$kb" -gt $((64 * 1024)) ]; then
        fail "recover of a crashed 20 MiB session peaked at $kb KB, more than 64 MB"
    else
        pass=$((pass + 1))
        echo "ok: recover of a crashed 20 MiB session ($stats)"
    fi
    rm -f "$work/crashed-20mib.mcap" "$work/crashed-out.mcap"
    # A site file of 2 MiB, and tables past their row and field limits.
    { printf '[booth]\n'; head -c $((2 << 20)) /dev/zero | tr '\0' '#'; } > "$work/huge.toml"
    bounded 100 1 "huge.toml: [0-9]+ bytes, more than the 1 MiB a site file may hold" -- "${R[@]}" config check "$work/huge.toml"
    { echo "R,G,B,X,Y,Z"; yes "1,2,3,4,5,6" | head -n 1100000; } > "$work/rows.csv"
    bounded 300 1 "rows.csv: 1100001 lines, more than the limit of 1048576 for a table" -- "${R[@]}" display fit "$work/rows.csv" --out "$work/p.json"
    { printf 'R'; head -c 10000 /dev/zero | tr '\0' ','; echo; } > "$work/wide.csv"
    bounded 100 1 "wide.csv:1: 10001 fields on one line, more than the limit of 4096" -- "${R[@]}" display fit "$work/wide.csv" --out "$work/p.json"
else
    fail "/usr/bin/time is missing: the bounded cases did not run"
fi
# replay --reprocess with an accelerometer scale that cannot be used (issue 32): a warning naming
# the device, the sample and the value, the samples counted; before, 1e308 and 0 showed the default
# tilt throughout, exit 0, without a word. NaN cannot be written in JSON: null is a damaged message.
v6="$2/recordings/samples/walk-v6.mcap"
for scale in 1e308 0; do
    python3 "$here/alter_recording.py" "$v6" "$work/scale-$scale.mcap" --accel-scale "$scale"
    out=$( (ulimit -v "$limit_kb"; timeout 60 "$replica" --log-level warn replay "$work/scale-$scale.mcap" --reprocess) 2>&1 >/dev/null)
    got=$?
    shown=0,0,0
    [ "$scale" = 1e308 ] && shown='1e\+308,1e\+308,1e\+308'
    want="249 accelerometer samples came out not finite.*accelerometer 'accelerometer \(simulated\) SIM-ACCEL-0001' sample 0: raw [^ ]+, scale $shown,"
    if [ $got -ne 0 ]; then
        fail "replay --reprocess with an accelerometer scale of $scale: exit $got: $out"
    elif ! grep -qE -- "$want" <<<"$out"; then
        fail "replay --reprocess with an accelerometer scale of $scale did not say /$want/: $out"
    else
        pass=$((pass + 1))
        echo "ok: accelerometer scale $scale named: $(printf '%s' "$out" | head -1 | cut -c1-160)..."
    fi
done
python3 "$here/alter_recording.py" "$v6" "$work/scale-null.mcap" --accel-scale null
expect 1 "scale-null.mcap: damaged /replica/raw/accel message \(sequence 0\).*must be number" -- \
    "${R[@]}" replay "$work/scale-null.mcap" --reprocess

# --- Every output a command writes goes through one writer (pipeline/base/output_file.h): never
# through a symbolic link (before, its target was overwritten), never into a FIFO (before, a hang),
# a device or a directory, and a full disk is an error with exit 1 (before, --snapshot and render
# --out wrote a short file or nothing and exited 0). The link's target must stay untouched.
out_dir="$work/outputs"
mkdir -p "$out_dir"
"$replica" --log-level error display synth --out "$out_dir/m.csv" >/dev/null || fail "display synth"
# writes OUTPUT_NAME EXT ARGS_BEFORE_THE_PATH...: the command with each bad path appended.
writes() {
    local label="$1" ext="$2"
    shift 2
    echo "# precious" > "$out_dir/target.$ext" # a valid site file too
    ln -sfn "$out_dir/target.$ext" "$out_dir/link.$ext"
    [ -e "$out_dir/fifo.$ext" ] || mkfifo "$out_dir/fifo.$ext"
    mkdir -p "$out_dir/adir.$ext"
    expect 1 "link.$ext: is a symbolic link; the .* never through a link" -- "${R[@]}" "$@" "$out_dir/link.$ext"
    [ "$(cat "$out_dir/target.$ext")" = "# precious" ] || fail "$label wrote through a symbolic link"
    # display fit checks its outputs before fitting ("not a regular file"); the rest when writing.
    expect 1 "fifo.$ext: (is a FIFO, not a .* file|not a regular file)" -- "${R[@]}" "$@" "$out_dir/fifo.$ext"
    expect 1 "adir.$ext: (is a directory, not a .* file|not a regular file)" -- "${R[@]}" "$@" "$out_dir/adir.$ext"
    if [ "$ext" != exr ]; then # render takes only a name ending in .exr
        expect 1 "/dev/null: (is a device, not a .* file|not a regular file)" -- "${R[@]}" "$@" /dev/null
    fi
    if [ -n "${full:-}" ]; then
        expect 1 "full/x.$ext: writing the .* failed: No space left on device; nothing written" -- \
            "${R[@]}" "$@" "$full/x.$ext"
        [ ! -e "$full/x.$ext" ] || fail "$label left a partial file on a full disk"
    fi
}
full=""
if mkdir -p "$out_dir/full" && mount -t tmpfs -o size=64k tmpfs "$out_dir/full" 2>/dev/null; then
    full="$out_dir/full"
    head -c 65536 /dev/zero > "$full/filler" 2>/dev/null # to the last block: not even 1 KB fits
else
    echo "note: no tmpfs can be mounted here (not root): the full-disk cases are skipped"
fi
writes "replay --digests" json replay "$sample" --no-progress --digests
writes "run --snapshot" png run --hal sim --output headless --size 48x30 --frames 2 --fast --snapshot
writes "render --out" exr render --scene "$data/scenes/metamer" --light d65 --out
writes "display fit --out" json display fit "$out_dir/m.csv" --out
writes "display fit --icc" icc display fit "$out_dir/m.csv" --out "$out_dir/p.json" --icc
writes "display synth --out" csv display synth --out
# Tracker points that fit exactly (booth = tracker), for the site file's rewrite.
printf '%s\n' 0,0.4,0.5,0,0.4,0.5 0.2,0.4,0.5,0.2,0.4,0.5 0,0.6,0.5,0,0.6,0.5 0,0.4,0.7,0,0.4,0.7 \
    0.2,0.6,0.7,0.2,0.6,0.7 -0.1,0.5,0.6,-0.1,0.5,0.6 > "$out_dir/points.csv"
writes "calibrate tracker --site" toml calibrate tracker --points "$out_dir/points.csv" --site
writes "spectral metamers --out" csv spectral metamers --count 1 --out
# writes_into LABEL FILE ARGS...: the command writes FILE into the folder appended to ARGS; FILE
# there a link, a FIFO and a directory in turn, then the folder on the full disk (no file left).
writes_into() {
    local label="$1" file="$2"
    shift 2
    local d="$out_dir/into-$label"
    rm -rf "$d" && mkdir -p "$d"
    echo "# precious" > "$out_dir/target-$file"
    ln -sfn "$out_dir/target-$file" "$d/$file"
    expect 1 "$file: is a symbolic link; the .* never through a link" -- "${R[@]}" "$@" "$d"
    [ "$(cat "$out_dir/target-$file")" = "# precious" ] || fail "$label wrote through a symbolic link"
    rm -f "$d/$file" && mkfifo "$d/$file"
    expect 1 "$file: is a FIFO, not a .* file" -- "${R[@]}" "$@" "$d"
    rm -f "$d/$file" && mkdir "$d/$file"
    expect 1 "$file: is a directory, not a .* file" -- "${R[@]}" "$@" "$d"
    if [ -n "${full:-}" ]; then
        expect 1 "full/$label/.*: writing the .* failed: No space left on device; nothing written" -- \
            "${R[@]}" "$@" "$full/$label"
        [ -z "$(find "$full/$label" -type f 2>/dev/null)" ] || fail "$label left a file on a full disk"
    fi
}
writes_into booth-generate booth.json booth generate --out
writes_into scene-generate scene.json scene generate --kind metamer --out
if [ -n "$full" ]; then umount "$full"; fi

# --- Every file a command reads goes through the bounded reader (pipeline/base/input_file.h): a
# FIFO (never a hang: expect runs each command under timeout), /dev/zero (a link to it, named as
# the command wants) and a directory are each refused in one line naming the file. Before, the
# points, the .ti1, the live display profile and an EXR opened by name hung on a FIFO.
in_dir="$work/inputs"
mkdir -p "$in_dir"
# reads CODE WHAT EXT ARGS...: the command with "@" in ARGS replaced by each bad file, named
# *.EXT; exit CODE (calibrate says a bad points file is a usage error, 2, as it always has).
reads() {
    local code="$1" what="$2" ext="$3"
    shift 3
    [ -e "$in_dir/fifo.$ext" ] || mkfifo "$in_dir/fifo.$ext"
    ln -sfn /dev/zero "$in_dir/zero.$ext"
    mkdir -p "$in_dir/adir.$ext"
    local bad a args
    for bad in fifo zero adir; do
        args=()
        for a in "$@"; do args+=("${a//@/$in_dir/$bad.$ext}"); done
        expect "$code" "$bad.$ext: is (a FIFO|a device|a directory), not a $what file" -- "${R[@]}" "${args[@]}"
    done
}
reads 2 "calibration points" csv calibrate tracker --points @ --dry-run
reads 1 "patch set \(\.ti1\)" ti1 display patches @ --out "$in_dir/r.ti3" --show-dir "$in_dir/show"
reads 1 "measurement" ti3 display fit @ --out "$in_dir/p.json"
reads 1 "display profile" json run --hal sim --output headless --size 48x30 --frames 1 --fast --display-profile @
reads 1 "site" toml config check @
# An EXR of the booth, and the booth's JSON, replaced.
for bad in fifo zero adir; do
    rm -rf "$in_dir/booth-$bad" && cp -r "$data/booth" "$in_dir/booth-$bad"
    exr=$(cd "$in_dir/booth-$bad" && ls ./*.exr | head -1)
    exr=${exr#./}
    rm -f "$in_dir/booth-$bad/$exr"
    case $bad in
        fifo) mkfifo "$in_dir/booth-$bad/$exr" ;;
        zero) ln -s /dev/zero "$in_dir/booth-$bad/$exr" ;;
        adir) mkdir "$in_dir/booth-$bad/$exr" ;;
    esac
    expect 1 "$exr: is (a FIFO|a device|a directory), not a OpenEXR file" -- "${R[@]}" render \
        --booth "$in_dir/booth-$bad" --scene "$data/scenes/metamer" --light d65 --out "$in_dir/x.exr"
done
# An EXR that declares 16384 x 16384 pixels in a few hundred bytes is refused before allocating.
python3 - "$data/booth" "$in_dir/booth-huge" <<'PY'
import glob, os, shutil, struct, sys
shutil.copytree(sys.argv[1], sys.argv[2], dirs_exist_ok=True)
f = sorted(glob.glob(os.path.join(sys.argv[2], "*.exr")))[0]
b = bytearray(open(f, "rb").read())
key = b"dataWindow\x00box2i\x00"
i = b.index(key) + len(key) + 4
b[i:i + 16] = struct.pack("<4i", 0, 0, 16383, 16383)
open(f, "wb").write(bytes(b))
PY
expect 1 "16384x16384 pixels; at most 16384 per side and 16777216 in all" -- "${R[@]}" render \
    --booth "$in_dir/booth-huge" --scene "$data/scenes/metamer" --light d65 --out "$in_dir/x.exr"

# replay shows a recording's text with its control characters escaped, as inspect does.
out=$("$replica" --log-level info replay "$rec/escapes.mcap" 2>&1)
if grep -q $'\x1b' <<<"$out"; then
    fail "replay printed a raw escape sequence from a recording"
elif ! grep -qF 'recorded by \x1b]0;owned\x07' <<<"$out"; then
    fail "replay did not show the escaped software string: $out"
else
    pass=$((pass + 1))
    echo "ok: replay escapes control characters"
fi

# inspect shows a recording's text with its control characters escaped.
out=$("$replica" inspect "$rec/escapes.mcap" 2>&1)
if grep -q $'\x1b' <<<"$out"; then
    fail "inspect printed a raw escape sequence from a recording"
elif ! grep -qF 'written by \x1b]0;owned\x07' <<<"$out"; then
    fail "inspect did not show the escaped software string: $out"
else
    pass=$((pass + 1))
    echo "ok: inspect escapes control characters"
fi

echo "hostile_input: $pass cases passed"
exit $status
