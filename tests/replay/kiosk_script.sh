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
# The unit: a configuration error (exit 78) is not restarted; transient faults are, within a start
# limit (not StartLimitIntervalSec=0, which retries forever).
unit="$(dirname "$script")/replica.service"
for line in "Restart=always" "RestartPreventExitStatus=78" "StartLimitBurst=10" \
        "StartLimitIntervalSec=600"; do
    if ! grep -qx "$line" "$unit"; then
        echo "FAIL: $unit lacks $line" >&2
        status=1
    fi
done
if command -v systemd-analyze >/dev/null; then
    # Clean but for the executable this machine has not installed.
    verify=$(systemd-analyze verify "$unit" 2>&1 | grep -v "/usr/bin/replica-kiosk is not executable")
    if [ -n "$verify" ]; then
        echo "FAIL: systemd-analyze verify $unit: $verify" >&2
        status=1
    fi
fi
[ $status -eq 0 ] && echo "ok: $out; $out2; the unit's restart policy"
exit $status
