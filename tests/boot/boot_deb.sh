#!/usr/bin/env bash
# boot.vm as the gallery meets the appliance: the package built from this build (cpack), booted
# with deploy/boot-test --deb, which first installs an older package running a real site and
# upgrades it to this one with deploy/kiosk/install (the site file, the sessions and a restart on
# the new binary checked), then checks the screen, kill -9 and the watchdog.
#   boot_deb.sh SOURCE_DIR BUILD_DIR VM_TIMEOUT_S
set -euo pipefail
src="$1"
build="$2"
timeout="$3"
if [ "$(id -u)" -ne 0 ]; then
    echo "boot.vm: skipped: needs root (the guest's files are made owned by root)" >&2
    exit 77
fi
out="$build/boot-deb"
rm -rf "$out" && mkdir -p "$out"
if ! cpack -G DEB --config "$build/CPackConfig.cmake" -B "$out" >"$out/cpack.log" 2>&1; then
    tail -20 "$out/cpack.log" >&2
    echo "boot.vm: FAIL cpack could not build the package (log: $out/cpack.log)" >&2
    exit 1
fi
debs=("$out"/replica_*_amd64.deb)
[ -f "${debs[0]}" ] || { echo "boot.vm: FAIL cpack made no replica_*_amd64.deb in $out" >&2; exit 1; }
echo "boot.vm: $(basename "${debs[0]}")"
exec "$src/deploy/boot-test" --deb "${debs[0]}" --build "$build" --timeout "$timeout"
