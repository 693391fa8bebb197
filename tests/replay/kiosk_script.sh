#!/usr/bin/env bash
# deploy/kiosk/replica-kiosk: runs 'replica run --kiosk' on the site file (its own or
# $REPLICA_CONFIG), passing extra options through.
set -uo pipefail
script="$1"
work="$2"
rm -rf "$work" && mkdir -p "$work"
status=0
out=$(REPLICA_BIN=/opt/replica "$script" --dry-run)
if [ "$out" != "/opt/replica run --kiosk --config /etc/replica/replica.toml" ]; then
    echo "FAIL: unexpected command: $out" >&2
    status=1
fi
out2=$(REPLICA_CONFIG="$work/site.toml" REPLICA_BIN=/opt/replica "$script" --dry-run --frames 5)
if [ "$out2" != "/opt/replica run --kiosk --config $work/site.toml --frames 5" ]; then
    echo "FAIL: unexpected command: $out2" >&2
    status=1
fi
[ $status -eq 0 ] && echo "ok: $out; $out2"
exit $status
