#!/usr/bin/env bash
# On a GPU machine: the frame table (frame_table.sh) headless on the vendor's EGL driver, from a
# bundle made by gpu_bundle.sh, at 960x600 and 1920x1200, paced at 30 Hz and --fast.
#
#   BUNDLE/gpu_frames.sh BUNDLE OUT        (from the repository's root: it reads data/)
#
# Unpacks BUNDLE/debs (libglvnd's EGL and GLES) into /, points glvnd at the NVIDIA vendor file
# (__EGL_VENDOR_LIBRARY_FILENAMES; /usr/local/nvidia/... as the device machines mount it, or any
# NVIDIA file under /usr/share/glvnd), takes a fallback library only where the machine lacks it,
# checks with a 5-frame run which GL_RENDERER the binary gets, then runs the table. OUT gets
# gpu_frames.log (everything printed), frames.md, frames.csv, clocks.csv (the GPU's clocks and load
# every 250 ms while the table runs) and logs.tgz (each run's log). The environment may set what
# frame_table.sh reads (PACING defaults to "paced fast" here) and TABLE_TIMEOUT (240 s for the
# whole table).
set -uo pipefail

if [ $# -ne 2 ] || [ "$1" = "-h" ] || [ "$1" = "--help" ]; then
    sed -n '2,14p' "$0" | sed 's/^# \{0,1\}//'
    exit 2
fi
bundle="$(cd "$1" && pwd)"
out="$2"
mkdir -p "$out"
out="$(cd "$out" && pwd)"
exec > >(tee "$out/gpu_frames.log") 2>&1
set -x
date -u
nvidia-smi -L
nvidia-smi --query-gpu=name,driver_version,clocks.sm,clocks.mem,clocks.max.sm --format=csv
uname -r
grep -E '^(PRETTY_NAME|VERSION_ID)=' /etc/os-release
ldd --version | head -n 1
nproc

# The GL loaders (glvnd), then the vendor's driver behind them.
for f in "$bundle"/debs/*.deb; do dpkg -x "$f" /; done
ldconfig
vendor=/usr/local/nvidia/share/glvnd/egl_vendor.d/10_nvidia.json
if [ ! -f "$vendor" ]; then
    vendor=$(find /usr/share/glvnd/egl_vendor.d /etc/glvnd/egl_vendor.d -name '*nvidia*.json' \
        2> /dev/null | head -n 1)
fi
if [ -n "$vendor" ]; then
    cat "$vendor"
    export __EGL_VENDOR_LIBRARY_FILENAMES="$vendor"
else
    echo "gpu_frames: no NVIDIA EGL vendor file; glvnd looks for vendors where it always does"
fi
for d in /usr/local/nvidia/lib64 /usr/local/nvidia/lib; do
    [ -d "$d" ] && LD_LIBRARY_PATH="${LD_LIBRARY_PATH:+$LD_LIBRARY_PATH:}$d"
done
find /usr/local/nvidia/lib64 -maxdepth 1 \( -iname '*egl*' -o -iname '*gles*' -o -iname '*glcore*' \
    -o -iname '*glsi*' \) 2> /dev/null

# The bundle's libraries; a fallback only for what the machine lacks (or has too old).
replica="$bundle/bin/replica"
extra=/tmp/gpu-fallback
rm -rf "$extra"
mkdir -p "$extra"
export LD_LIBRARY_PATH="$bundle/lib:$extra${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}"
for pass in 1 2; do
    for name in $(ldd "$replica" 2>&1 | sed -n -e 's/^[[:space:]]*\([^[:space:]]*\) => not found$/\1/p' \
        -e 's/^.*: \([^:]*\): version .* not found .*$/\1/p' | xargs -r -n 1 basename | sort -u); do
        if [ -f "$bundle/fallback/$name" ]; then
            echo "gpu_frames: pass $pass: the bundle's $name (missing or too old here)"
            cp "$bundle/fallback/$name" "$extra/"
        fi
    done
done
ldd "$replica"
if ldd "$replica" 2>&1 | grep -q 'not found'; then
    echo "gpu_frames: libraries still missing (above); stopping"
    exit 1
fi

export REPLICA_DATA_DIR="$PWD/data" XDG_CACHE_HOME=/tmp/replica-cache
smoke=(run --hal sim --output headless --scene "$REPLICA_DATA_DIR/scenes/metamer" --frames 5
    --size 64x40 --fast)
if ! timeout 60 "$replica" "${smoke[@]}"; then
    echo "gpu_frames: the 5-frame run failed; what the loader did:"
    LD_DEBUG=libs timeout 60 "$replica" "${smoke[@]}" 2>&1 | grep -i -E 'egl|gles|nvidia|glvnd|error' |
        tail -n 60
    exit 1
fi

export PACING="${PACING:-paced fast}" RUN_TIMEOUT="${RUN_TIMEOUT:-45}"
table=/tmp/gpu-frames
rm -rf "$table"
# The clocks while the table runs (a paced frame leaves the GPU mostly idle).
nvidia-smi --query-gpu=timestamp,clocks.sm,clocks.mem,utilization.gpu,power.draw --format=csv \
    -lms 250 > "$out/clocks.csv" 2>&1 &
sampler=$!
timeout "${TABLE_TIMEOUT:-240}" bash "$bundle/frame_table.sh" "$replica" "$table"
code=$?
kill "$sampler"
nvidia-smi --query-gpu=name,clocks.sm,clocks.mem,temperature.gpu,power.draw --format=csv
cp "$table/frames.md" "$table/frames.csv" "$out/" 2> /dev/null
tar czf "$out/logs.tgz" -C "$table" .
exit "$code"
