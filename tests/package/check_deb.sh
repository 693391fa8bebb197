#!/usr/bin/env bash
# Builds replica_<version>_amd64.deb with cpack and checks it without installing it: control
# fields, conffiles, maintainer scripts, contents (documentation and a manual page per command,
# each rendered by man), the unpacked binary running on its own data, the hardening of the binary
# (read with readelf), the unit's exposure, and lintian without errors or warnings.
#   check_deb.sh BUILD_DIR VERSION WORK_DIR [HARDENED]
# HARDENED (ON by default) is the build's REPLICA_HARDENED: OFF for the sanitizer and libFuzzer
# builds, whose package is never shipped and whose binary is not linked -z now.
set -uo pipefail
build="$1"
version="$2"
work="$3"
hardened="${4:-ON}"
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
[ "$(field Suggests)" = argyll ] || fail "Suggests: '$(field Suggests)', expected argyll"
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
    ./usr/share/replica/scenes/colorchecker/scene.json ./usr/share/doc/replica/appliance.md \
    ./usr/share/doc/replica/display.md ./usr/share/doc/replica/recordings.md \
    ./usr/share/doc/replica/foxglove-layout.json ./usr/share/doc/replica/copyright \
    ./usr/share/man/man1/replica.1.gz ./usr/share/metainfo/org.example.replica.metainfo.xml; do
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
grep -q "display.allow_synthetic: the kiosk refuses a live run" <<<"$out" ||
    fail "the shipped site file: $out"
[ "$(echo "$out" | grep -c "replica.toml:")" -eq 1 ] || fail "the shipped site file: $out"
log=$(env -u REPLICA_DATA_DIR "$root/usr/bin/replica" run --frames 2 --fast 2>&1) ||
    fail "the unpacked binary cannot run: $log"
grep -q "data $root/usr/share/replica\$" <<<"$log" ||
    fail "the unpacked binary did not use its own data: $(echo "$log" | grep data)"

# The copyright file names the licence of the top-level LICENSE (Apache-2.0).
grep -q '^License: Apache-2.0$' "$root/usr/share/doc/replica/copyright" ||
    fail "debian/copyright does not name the Apache-2.0 licence"

# A manual page for the program and for each command its --help lists, each rendered by man
# without a warning.
mapfile -t commands < <(env -u REPLICA_DATA_DIR "$root/usr/bin/replica" --help |
    sed -n '/^Subcommands:/,$p' | sed -n 's/^  \([a-z][a-z-]*\)  .*/\1/p')
[ ${#commands[@]} -ge 10 ] || fail "--help lists only ${#commands[@]} commands: ${commands[*]}"
pages=0
for page in replica replica-kiosk "${commands[@]/#/replica-}"; do
    file="$root/usr/share/man/man1/$page.1.gz"
    [ -f "$file" ] || fail "no manual page $page(1) in the package"
    if command -v man >/dev/null; then
        text=$(MANWIDTH=80 man --warnings -l "$file" 2>"$work/man.err") || fail "man -l $page.1.gz failed"
        [ ! -s "$work/man.err" ] || fail "man warns on $page(1): $(head -3 "$work/man.err")"
        grep -q "^NAME" <<<"$text" || fail "$page(1) has no NAME section"
        echo "$text" | grep -A1 "^NAME" | grep -Eq "^ +$page +- " || fail "$page(1)'s NAME is not '$page - ...'"
        grep -Eq -- "^ +-" <<<"$text" || fail "$page(1) lists no options"
    fi
    pages=$((pages + 1))
done
echo "manual pages: $pages (replica, replica-kiosk and ${#commands[@]} commands)"

# Hardening, read from the binary itself: PIE (ELF type DYN with the PIE flag), full RELRO (a
# GNU_RELRO segment and BIND_NOW), fortified libc calls (*_chk) and the stack protector.
if [ "$hardened" != ON ]; then
    echo "hardening: not checked (this build is not hardened: REPLICA_HARDENED=$hardened)"
elif command -v readelf >/dev/null; then
    bin="$root/usr/bin/replica"
    # Read once into variables: 'readelf | grep -q' fails under pipefail when grep stops early.
    header=$(readelf -h "$bin")
    dynamic=$(readelf -d "$bin")
    segments=$(readelf -l "$bin")
    symbols=$(readelf --dyn-syms -W "$bin")
    grep -q 'Type: *DYN' <<<"$header" || fail "replica is not position independent (PIE)"
    grep -q 'FLAGS_1.*PIE' <<<"$dynamic" || fail "replica lacks the PIE flag"
    grep -q GNU_RELRO <<<"$segments" || fail "replica has no RELRO segment (-z relro)"
    grep -Eq 'BIND_NOW|FLAGS.*NOW' <<<"$dynamic" || fail "replica is not bound now (-z now)"
    fortified=$(grep -Ec ' __[a-z]+_chk@' <<<"$symbols")
    [ "$fortified" -gt 0 ] || fail "replica calls no fortified functions (_FORTIFY_SOURCE)"
    grep -q '__stack_chk_fail' <<<"$symbols" || fail "replica has no stack protector"
    echo "hardening: PIE, RELRO, BIND_NOW, $fortified fortified functions, stack protector"
fi

# The unit caps what a fault can take and ranks the kiosk above ordinary processes (issue 32):
# MemoryHigh below MemoryMax, both sizes; a task limit; a negative nice; the error probe's thread
# allowed to lower itself.
unit="$root/lib/systemd/system/replica.service"
setting() { sed -n "s/^$1=//p" "$unit" | tail -1; }
bytes() { numfmt --from=iec "$1" 2>/dev/null; }
high=$(bytes "$(setting MemoryHigh)") || true
max=$(bytes "$(setting MemoryMax)") || true
[ -n "$max" ] && [ "$max" -ge $((256 << 20)) ] || fail "MemoryMax='$(setting MemoryMax)': no size of at least 256M"
[ -n "$high" ] && [ "$high" -lt "$max" ] || fail "MemoryHigh='$(setting MemoryHigh)' is not below MemoryMax"
# Not below what a 1920x1200 panel needs: its kiosk's measured peak (999 MiB, docs/appliance.md,
# "Resource bounds") before the kernel starts to reclaim.
[ "$high" -ge $((1024 << 20)) ] ||
    fail "MemoryHigh='$(setting MemoryHigh)': below 1G, the 1920x1200 kiosk's measured peak"
ioclass=$(setting IOSchedulingClass)
[ "$ioclass" = best-effort ] || fail "IOSchedulingClass='$ioclass': the unit says best-effort (docs/limits.md)"
tasks=$(setting TasksMax)
[[ "$tasks" =~ ^[0-9]+$ ]] && [ "$tasks" -ge 64 ] && [ "$tasks" -le 1024 ] || fail "TasksMax='$tasks'"
nice=$(setting Nice)
[[ "$nice" =~ ^-[0-9]+$ ]] || fail "Nice='$nice': the kiosk must outrank ordinary processes"
grep -q '^SystemCallFilter=setpriority sched_setscheduler$' "$unit" ||
    fail "the error probe's thread may not lower its own priority (SystemCallFilter)"
echo "unit bounds: MemoryHigh $(setting MemoryHigh), MemoryMax $(setting MemoryMax), TasksMax $tasks, Nice $nice," \
    "IOSchedulingClass $ioclass"
if command -v systemd-analyze >/dev/null; then
    score=$(systemd-analyze security --offline=true "$unit" 2>/dev/null |
        sed -n 's/.*Overall exposure level for replica.service: \([0-9.]*\).*/\1/p')
    [ -n "$score" ] || fail "systemd-analyze gave no score"
    awk -v s="$score" 'BEGIN { exit !(s <= 3.0) }' || fail "exposure $score > 3.0"
    echo "systemd-analyze security: $score"
    systemd-analyze verify "$unit" 2>&1 | grep -v -e 'replica-kiosk' -e 'Command /usr/bin' || true
fi
if command -v lintian >/dev/null; then
    lintian --no-tag-display-limit "$deb" >"$work/lintian.log" 2>&1 || true
    if grep -E '^(E|W):' "$work/lintian.log"; then
        fail "lintian errors or warnings (log: $work/lintian.log)"
    fi
    echo "lintian: no errors or warnings ($(grep -c '^[IPX]:' "$work/lintian.log") notes: $work/lintian.log)"
fi
echo "ok"
