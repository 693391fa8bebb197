#!/usr/bin/env bash
# The udev rule that opens hidraw nodes of HID eye/head trackers to 'plugdev': its PROGRAM, run on
# fake sysfs report descriptors, must match a tracker (Usage Page 0x12 in one- or two-byte form)
# and must not match a keyboard or a mouse.
set -euo pipefail
rules="$1"
work="$2"
rm -rf "$work" && mkdir -p "$work"
line=$(grep '^SUBSYSTEM=="hidraw".*PROGRAM=' "$rules")
script=$(printf '%s' "$line" | sed -E "s/.*PROGRAM=\"\/bin\/sh -c '([^']*)'\".*/\1/")
patterns=$(printf '%s' "$line" | sed -E 's/.*RESULT=="([^"]*)".*/\1/')
[ -n "$script" ] && [ -n "$patterns" ] || { echo "FAIL: cannot read the hidraw rule" >&2; exit 1; }
check() {
    local name="$1" bytes="$2" want="$3"
    mkdir -p "$work/sys/$name/device"
    printf "$bytes" > "$work/sys/$name/device/report_descriptor"
    local cmd="${script//\/sys\/class\/hidraw/$work/sys}"
    cmd="${cmd//%k/$name}"
    local result
    result=$(sh -c "$cmd")
    local got=no
    IFS='|' read -ra alts <<< "$patterns"
    for p in "${alts[@]}"; do
        # shellcheck disable=SC2053
        if [[ "$result" == $p ]]; then
            got=yes
        fi
    done
    if [ "$got" != "$want" ]; then
        echo "FAIL: $name ('$result'): matched=$got, want $want" >&2
        exit 1
    fi
}
check hidraw0 '\x05\x12\x09\x01\xa1\x01' yes   # eye tracker, Usage Page (0x12)
check hidraw1 '\x06\x12\x00\x09\x02' yes       # head tracker, two-byte Usage Page
check hidraw2 '\x05\x01\x09\x06\xa1\x01' no    # keyboard
check hidraw3 '\x05\x01\x09\x02\xa1\x01' no    # mouse
check hidraw4 '\x06\x12\x01\x09\x01' no        # page 0x0112, not 0x12
echo "ok: the hidraw rule matches trackers only"
