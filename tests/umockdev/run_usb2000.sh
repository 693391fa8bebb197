#!/usr/bin/env bash
# Runs the USB2000+ libusb test inside umockdev-run; 77 (skipped) without umockdev.
set -euo pipefail
test_bin="$1"
src="$2"
work="$3"
if ! command -v umockdev-run >/dev/null 2>&1; then
    echo "umockdev-run not installed (Debian package 'umockdev'): skipped"
    exit 77
fi
mkdir -p "$work"
python3 "$src/make_usb2000_ioctl.py" > "$work/usb2000.ioctl"
# ASan builds: the preload library comes first in LD_PRELOAD, which ASan otherwise refuses.
export ASAN_OPTIONS="${ASAN_OPTIONS:+$ASAN_OPTIONS:}verify_asan_link_order=0"
exec umockdev-run -d "$src/usb2000.umockdev" -i "/dev/bus/usb/001/002=$work/usb2000.ioctl" \
    -- "$test_bin"
