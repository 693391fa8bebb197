#!/usr/bin/env bash
# ArgyllCMS 2.3 reads what 'replica display fit --icc' writes, and the fit holds up against
# colprof's on the same readings. A display simulated by Argyll itself (fakeread through its own
# ref/sRGB.icm, noise-free) is read on targen's ordinary set (-d3 -f200: four levels per ramp) and
# on the same set with 9-step ramps (-s9); 'replica display fit' fits both (the relative readings
# scaled by --white-cdm2) and writes ICC v2.4. Checked: iccdump reads the profile without a warning
# and shows the tags of a v2 display profile; xicclu's forward values (absolute intent) equal
# 'replica display forward' at a few drive values; profcheck's CIEDE2000 against the fitting
# readings and against 100 held-out colours (targen -q) stays within the bounds below; colprof's
# matrix/shaper (-as) and LUT (-al) profiles from the same readings are checked the same way and
# printed beside ours (docs/display.md, "ArgyllCMS files and ICC", records the figures).
# Usage: argyll_profile.sh REPLICA WORKDIR. Exit 77 (skip) without ArgyllCMS.
set -euo pipefail
replica="$1"
work="$2"
for tool in targen fakeread iccdump profcheck xicclu colprof; do
    if ! command -v "$tool" >/dev/null 2>&1; then
        echo "SKIP: ArgyllCMS's $tool is not installed (deploy/install-deps installs argyll)"
        exit 77
    fi
done
ref=""
for dir in /usr/share/color/argyll/ref /usr/share/argyllcms/ref /usr/local/share/argyllcms/ref; do
    [ -f "$dir/sRGB.icm" ] && ref="$dir/sRGB.icm" && break
done
if [ -z "$ref" ]; then
    echo "SKIP: ArgyllCMS's ref/sRGB.icm not found"
    exit 77
fi
rm -rf "$work" && mkdir -p "$work" && cd "$work"
fail() {
    echo "FAIL: $*" >&2
    exit 1
}

# Bounds on profcheck's CIEDE2000 (avg / peak), about twice what was measured (ArgyllCMS 2.3.1,
# lcms2 2.14, Debian bookworm; the data are noise-free and targen's sets deterministic, so the
# margin is for another Argyll's or lcms2's rounding and the fit's numerics, not for noise); a
# real regression (a wrong adaptation, v2 wtpt or TRC) costs several units. colprof's figures are
# printed, not bounded.
# -s9 set, measured: avg 0.071 on its own readings, 0.080 held out; peak 0.187, 0.192.
max_avg_ramps=0.16
max_peak_ramps=0.40
# -d3 -f200, GOG from four levels (sRGB's linear toe is not a GOG), measured: avg 0.468 on its
# own readings, 0.512 held out; peak 1.912, 0.979.
max_avg_ordinary=1.00
max_peak_ordinary=3.00

white=120 # cd/m^2, the luminance given for the relative readings
targen -v0 -d3 -f200 ordinary >/dev/null
targen -v0 -d3 -s9 -f200 ramps >/dev/null
targen -v0 -d3 -e1 -B1 -f100 -q held >/dev/null
for set in ordinary ramps held; do
    fakeread -v0 "$ref" "$set" >/dev/null
done

# The relative readings without a luminance: a clear error that names the option.
if "$replica" --log-level warn display fit ramps.ti3 --out none.json 2>err.txt; then
    fail "a .ti3 without LUMINANCE_XYZ_CDM2 fitted without --white-cdm2"
fi
grep -q -- "--white-cdm2" err.txt || fail "the error does not name --white-cdm2: $(cat err.txt)"

# targen's three-table .ti1 shown by 'display patches' (headless, readings typed): fakeread's
# readings of the same set, in its order, scaled to cd/m^2, make a .ti3 that fits without
# --white-cdm2 (display patches writes LUMINANCE_XYZ_CDM2).
awk -v w="$white" '/^BEGIN_DATA$/ { d = 1; next } /^END_DATA$/ { exit }
    d { printf "%.6f %.6f %.6f\n", $5 * w / 100, $6 * w / 100, $7 * w / 100 }' ordinary.ti3 |
    "$replica" --log-level warn display patches ordinary.ti1 --out shown.ti3 --show-dir show \
        --settle-ms 0 >/dev/null || fail "display patches ordinary.ti1"
"$replica" --log-level warn display fit shown.ti3 --out shown.json >/dev/null ||
    fail "display fit of what display patches read"

# The .ti1 replica writes (lcms2's IT8 writer) is one Argyll reads: fakeread measures it.
"$replica" --log-level warn display patches --make-set made.ti1 --step 15 --colours 20 >/dev/null ||
    fail "display patches --make-set"
fakeread -v0 "$ref" made >/dev/null || fail "fakeread cannot read replica's made.ti1"
"$replica" --log-level warn display fit made.ti3 --white-cdm2 "$white" --out made.json >/dev/null ||
    fail "display fit of fakeread's readings of replica's own set"

# profcheck's CIEDE2000 "avg peak" of a profile against a .ti3.
de00() {
    profcheck -v1 -k "$1" "$2" 2>&1 |
        awk '/Profile check complete/ { gsub(",", ""); for (i = 1; i <= NF; ++i) {
                 if ($i == "max.") p = $(i + 2); if ($i == "avg.") a = $(i + 2) } }
             END { if (a == "") exit 1; print a, p }'
}
# xicclu's absolute XYZ (white Y = 100) at device values 0-1 "R G B" per line on stdin.
lookup() { xicclu -v0 -ff -ia -pX "$1" | awk 'NF == 3 { print $1, $2, $3; next } { exit 1 }'; }
within() { awk -v a="$1" -v b="$2" 'BEGIN { exit !(a <= b) }'; }

drives="0 0 0
1 1 1
0.5 0.5 0.5
1 0 0
0 1 0
0 0 1
0.25 0.6 0.9
0.8 0.3 0.1"

for set in ordinary ramps; do
    "$replica" --log-level warn display fit "$set.ti3" --white-cdm2 "$white" --out "$set.json" \
        --icc "$set.icc" >"$set.fit.txt" || fail "display fit $set.ti3"
    # iccdump: reads it, says nothing is wrong, and shows a v2.4 display profile's tags.
    iccdump -v3 "$set.icc" >"$set.dump" 2>&1 || fail "iccdump cannot read $set.icc"
    if grep -qi "warning\|error\|not supported" "$set.dump"; then
        fail "iccdump on $set.icc: $(grep -i 'warning\|error\|not supported' "$set.dump" | head -3)"
    fi
    grep -q "Version      = 2.4" "$set.dump" || fail "$set.icc is not v2.4"
    grep -q "Device Class = Display" "$set.dump" || fail "$set.icc is not a display profile"
    for tag in desc wtpt rXYZ gXYZ bXYZ rTRC gTRC bTRC chad lumi; do
        grep -q "sig      '$tag'" "$set.dump" || fail "$set.icc has no $tag tag"
    done
    grep -A2 "sig      'desc'" "$set.dump" | grep -q "type     'desc'" ||
        fail "$set.icc's description is not a v2 textDescription"
    # xicclu's forward values against the model's own (absolute cd/m^2, scaled to white Y = 100).
    white_y=$("$replica" display forward "$set.json" --rgb 255,255,255 --json |
        sed 's/.*"xyz":\[\([^]]*\)\].*/\1/' | cut -d, -f2)
    lookup "$set.icc" <<<"$drives" >"$set.xicclu"
    row=0
    while read -r r g b; do
        row=$((row + 1))
        counts=$(awk -v r="$r" -v g="$g" -v b="$b" 'BEGIN { printf "%.6f,%.6f,%.6f", r*255, g*255, b*255 }')
        ours=$("$replica" display forward "$set.json" --rgb "$counts" --json |
            sed 's/.*"xyz":\[\([^]]*\)\].*/\1/' | tr ',' ' ')
        read -r ix iy iz < <(sed -n "${row}p" "$set.xicclu")
        awk -v o="$ours" -v w="$white_y" -v ix="$ix" -v iy="$iy" -v iz="$iz" -v d="$r $g $b" \
            -v set="$set" 'BEGIN { split(o, m, " "); x = m[1] * 100 / w; y = m[2] * 100 / w;
                z = m[3] * 100 / w; e = (x - ix)^2 + (y - iy)^2 + (z - iz)^2;
                printf "%s drive %s: replica %.3f %.3f %.3f, xicclu %.3f %.3f %.3f\n", set, d,
                       x, y, z, ix, iy, iz;
                # The curv tags hold 16-bit values, the colorants s15Fixed16: 0.05 of Y = 100.
                exit !(sqrt(e) < 0.05) }' ||
            fail "$set: xicclu and replica display forward differ at $r $g $b"
    done <<<"$drives"
done

# colprof on the same readings as the -s9 fit: matrix/shaper and LUT (medium quality).
cp ramps.ti3 argyll_shaper.ti3
cp ramps.ti3 argyll_lut.ti3
colprof -v0 -qm -as argyll_shaper >/dev/null
colprof -v0 -qm -al argyll_lut >/dev/null
for p in argyll_shaper argyll_lut; do
    iccdump "$p.icc" >/dev/null || fail "iccdump cannot read colprof's $p.icc"
done

echo "profcheck CIEDE2000 (avg peak): fitting readings / 100 held-out colours (targen -q)"
for p in ordinary ramps argyll_shaper argyll_lut; do
    fitset=$p
    [ "$p" = ordinary ] || fitset=ramps
    read -r fa fp < <(de00 "$fitset.ti3" "$p.icc") || fail "profcheck $fitset.ti3 $p.icc"
    read -r ha hp < <(de00 held.ti3 "$p.icc") || fail "profcheck held.ti3 $p.icc"
    echo "$p: $fa $fp / $ha $hp"
    lookup "$p.icc" <<<"$drives" | paste -d' ' <(echo "$drives" | tr ' ' ',') - |
        sed "s/^/  $p xicclu /"
    case $p in
    ramps)
        for v in "$fa $max_avg_ramps" "$ha $max_avg_ramps" "$fp $max_peak_ramps" "$hp $max_peak_ramps"; do
            # shellcheck disable=SC2086
            within $v || fail "replica's -s9 profile: profcheck dE00 $v (value, bound)"
        done
        ;;
    ordinary)
        for v in "$fa $max_avg_ordinary" "$ha $max_avg_ordinary" "$fp $max_peak_ordinary" "$hp $max_peak_ordinary"; do
            # shellcheck disable=SC2086
            within $v || fail "replica's -d3 -f200 profile: profcheck dE00 $v (value, bound)"
        done
        ;;
    esac
done
grep -q "short ramps: R 4 G 4 B 4" ordinary.fit.txt || fail "the -d3 -f200 fit does not say its ramps were short"
echo "PASS: ArgyllCMS reads replica's v2.4 profiles; profcheck within bounds"
