#!/usr/bin/env bash
# Packs a replica binary for a GPU machine that has the vendor's driver but none of replica's
# libraries and no package registry: the frame table (frame_table.sh) then runs there with
# gpu_frames.sh.
#
#   tests/benchmarks/gpu_bundle.sh REPLICA DEST
#
# DEST (made anew) gets: bin/replica (stripped); lib/, every library `ldd REPLICA` names except
# glibc's own, libstdc++/libgcc_s and the GL ones; fallback/, libstdc++, libgcc_s, libgbm and
# libdrm, which gpu_frames.sh uses only where the machine lacks them (or has too old a libstdc++);
# debs/, libglvnd's EGL and GLES loaders as amd64 .debs (apt-get download: needs this machine's
# package lists), which gpu_frames.sh unpacks there so that EGL reaches the vendor's driver
# through glvnd; and frame_table.sh and gpu_frames.sh themselves. The data/ it reads is the
# repository's, so DEST goes inside the checkout that travels (an ignored folder). Prints DEST's
# size.
set -euo pipefail

if [ $# -ne 2 ] || [ "$1" = "-h" ] || [ "$1" = "--help" ]; then
    sed -n '2,15p' "$0" | sed 's/^# \{0,1\}//'
    exit 2
fi
replica="$1"
dest="$2"
here="$(cd "$(dirname "$0")" && pwd)"
if [ ! -x "$replica" ]; then
    echo "gpu_bundle: $replica is not an executable replica binary" >&2
    exit 1
fi
if ldd "$replica" | grep -q 'not found'; then
    echo "gpu_bundle: $replica has libraries missing here:" >&2
    ldd "$replica" | grep 'not found' >&2
    exit 1
fi
rm -rf "$dest"
mkdir -p "$dest/bin" "$dest/lib" "$dest/fallback" "$dest/debs"
strip -o "$dest/bin/replica" "$replica"

# glibc's own come from the machine; the GL loaders from the debs (glvnd, then the vendor's
# driver); libstdc++ and the KMS output's GBM/DRM from the machine where it has them.
system='^(linux-vdso|ld-linux|libc|libm|libpthread|libdl|librt|libresolv|libutil)\.so'
gl='^(libEGL|libGLESv2|libGLdispatch|libGLX|libGL|libOpenGL)\.so'
fallback='^(libstdc\+\+|libgcc_s|libgbm|libdrm)\.so'
ldd "$replica" | awk '$2 == "=>" && $3 ~ /^\// {print $1, $3}' | while read -r name path; do
    if [[ "$name" =~ $system ]] || [[ "$name" =~ $gl ]]; then
        continue
    elif [[ "$name" =~ $fallback ]]; then
        cp -L "$path" "$dest/fallback/$name"
    else
        cp -L "$path" "$dest/lib/$name"
    fi
done
(cd "$dest/debs" && apt-get download libegl1 libgles2 libglvnd0 libopengl0 libgl1 libglx0 > /dev/null)
cp "$here/frame_table.sh" "$here/gpu_frames.sh" "$dest/"
count() { find "$dest/$1" -type f | wc -l; }
echo "gpu_bundle: $dest: $(du -sh "$dest" | cut -f1) ($(count lib) libraries, $(count fallback)" \
    "fallbacks, $(count debs) debs)"
