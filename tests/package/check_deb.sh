#!/usr/bin/env bash
# Builds replica_<version>_amd64.deb with cpack and checks it without installing it.
#   check_deb.sh BUILD_DIR VERSION WORK_DIR
set -uo pipefail
build="$1"
version="$2"
work="$3"
rm -rf "$work" && mkdir -p "$work"
fail() {
    echo "FAIL: $*" >&2
    exit 1
}
for tool in cpack dpkg-deb; do
    command -v "$tool" >/dev/null || { echo "skip: no $tool"; exit 77; }
done
if ! cpack -G DEB --config "$build/CPackConfig.cmake" -B "$work" >"$work/cpack.log" 2>&1; then
    tail -20 "$work/cpack.log" >&2
    fail "cpack failed (log: $work/cpack.log)"
fi
deb="$work/replica_${version}_amd64.deb"
[ -f "$deb" ] || fail "no $deb; cpack made: $(ls "$work")"
echo "package: $(basename "$deb"), $(stat -c %s "$deb") bytes"

field() { dpkg-deb -f "$deb" "$1"; }
[ "$(field Package)" = replica ] || fail "Package: $(field Package)"
[ "$(field Version)" = "$version" ] || fail "Version: $(field Version), expected $version"
[ "$(field Architecture)" = amd64 ] || fail "Architecture: $(field Architecture)"
depends=$(field Depends)
for dep in libc6 libstdc++6 libegl1 libusb-1.0-0 libsystemd0 adduser udev libegl-mesa0; do
    case ", $depends," in
    *", $dep"[\ ,\(]*) ;;
    *) fail "Depends lacks $dep: $depends" ;;
    esac
done

dpkg-deb -e "$deb" "$work/control"
[ "$(cat "$work/control/conffiles")" = /etc/replica/replica.toml ] ||
    fail "conffiles: $(cat "$work/control/conffiles")"
for script in postinst prerm postrm; do
    [ -x "$work/control/$script" ] || fail "no executable $script"
    sh -n "$work/control/$script" || fail "$script: syntax"
done
grep -q 'adduser --system' "$work/control/postinst" || fail "postinst creates no system user"
grep -q 'udevadm trigger' "$work/control/postinst" || fail "postinst does not trigger udev"

dpkg-deb -c "$deb" | awk '{print $1, $2, $NF}' >"$work/contents"
for path in ./usr/bin/replica ./usr/bin/replica-kiosk ./etc/replica/replica.toml \
    ./lib/systemd/system/replica.service ./lib/udev/rules.d/60-replica.rules \
    ./usr/share/replica/booth/booth.json ./usr/share/replica/displays/wide-ips-synthetic.json \
    ./usr/share/replica/scenes/colorchecker/scene.json ./usr/share/doc/replica/appliance.md; do
    grep -q " $path\$" "$work/contents" || fail "$path is not in the package"
done
grep -q '^-rwxr-xr-x root/root ./usr/bin/replica$' "$work/contents" ||
    fail "/usr/bin/replica: $(grep ' ./usr/bin/replica$' "$work/contents")"
if grep -E ' \./(usr/local|home|work|tmp)/' "$work/contents"; then
    fail "files outside the system folders"
fi
echo "contents: $(wc -l <"$work/contents") entries, $(grep -c '/usr/share/replica/' "$work/contents") under /usr/share/replica"

# Unpacked anywhere, the binary finds its data next to itself (../share/replica), not the
# source tree it was built from.
dpkg-deb -x "$deb" "$work/root"
root="$work/root"
out=$(env -u REPLICA_DATA_DIR "$root/usr/bin/replica" --version) || fail "--version failed"
case "$out" in
"replica $version (git "*")") ;;
*) fail "--version says '$out'" ;;
esac
echo "version: $out"
# As shipped the kiosk refuses the synthetic display profile (until the panel's is set), and the
# check, resolving what the kiosk resolves with the package's own data, says exactly that.
out=$(env -u REPLICA_DATA_DIR "$root/usr/bin/replica" config check "$root/etc/replica/replica.toml" 2>&1)
echo "$out" | grep -q "display.allow_synthetic: the kiosk refuses a live run" ||
    fail "the shipped site file: $out"
[ "$(echo "$out" | grep -c "replica.toml:")" -eq 1 ] || fail "the shipped site file: $out"
log=$(env -u REPLICA_DATA_DIR "$root/usr/bin/replica" run --frames 2 --fast 2>&1) ||
    fail "the unpacked binary cannot run: $log"
echo "$log" | grep -q "data $root/usr/share/replica\$" ||
    fail "the unpacked binary did not use its own data: $(echo "$log" | grep data)"

if command -v systemd-analyze >/dev/null; then
    unit="$root/lib/systemd/system/replica.service"
    score=$(systemd-analyze security --offline=true "$unit" 2>/dev/null |
        sed -n 's/.*Overall exposure level for replica.service: \([0-9.]*\).*/\1/p')
    [ -n "$score" ] || fail "systemd-analyze gave no score"
    awk -v s="$score" 'BEGIN { exit !(s <= 3.0) }' || fail "exposure $score > 3.0"
    echo "systemd-analyze security: $score"
    systemd-analyze verify "$unit" 2>&1 | grep -v -e 'replica-kiosk' -e 'Command /usr/bin' || true
fi
if command -v lintian >/dev/null; then
    lintian --no-tag-display-limit "$deb" >"$work/lintian.log" 2>&1 || true
    if grep '^E:' "$work/lintian.log"; then
        fail "lintian errors (log: $work/lintian.log)"
    fi
    echo "lintian: $(grep -c '^W:' "$work/lintian.log") warnings, no errors"
fi
echo "ok"
