#!/usr/bin/env bash
# Checks the allowed dependency edges between layers (style guide section 1): pipeline and hal include
# nothing of the other layers (hal may use pipeline/base only); recordings only hal and pipeline/base;
# state/ (sensor samples -> SceneState) sits between hal and the renderer: it may include hal and the
# pipeline below render/, and nothing but platform includes it (hal -> state -> render).
# Inside pipeline/, its folders are in an order (pipeline/CMakeLists.txt): each may include only itself
# and the folders before it; only pipeline/render/ and platform/output/ include GL, EGL, GBM or DRM
# headers; no run-time file includes an offline tool (pipeline/offline/: fits, studies, generators),
# where run-time is all of pipeline/ but offline/, state/, hal/, recordings/ and platform/ but cli/;
# every top-level folder is one this check knows.
#
# It reads every include the compiler would: <...> and "..." (a quoted path relative to the including
# file is resolved against the tree), any spacing (`# include`, `#include  <...>`), in .h, .hpp,
# .inl, .ipp, .hh, .c, .cc, .cxx and .cpp files. tests/layering_check_test.sh plants one violation of
# each kind and shows this check failing on it.
set -uo pipefail
root="${1%/}"
status=0
fail() {
    echo "FAIL: $1" >&2
    [ -z "${2:-}" ] || echo "$2" >&2
    status=1
}

# Every top-level folder is a layer or a known support folder (cmake/: CMake modules, no sources):
# a new layer needs its edges here.
known_top=(build cmake data deploy docs hal pipeline platform recordings state tests tools)
for dir in "$root"/*/; do
    top=$(basename "$dir")
    if [[ " ${known_top[*]} " != *" $top "* ]]; then
        fail "$top/ is a top-level folder this check does not know: add it to known_top in \
tests/layering_check.sh with the layers it may include (and checks for them)"
    fi
done

# All includes of the layers as "file:line:target", file relative to the root and target as written
# between <> or "" (a quoted one resolved relative to its file when it names a file there).
layers=(hal pipeline platform recordings state)
sources=()
for layer in "${layers[@]}"; do [ -d "$root/$layer" ] && sources+=("$root/$layer"); done
includes=$(grep -rnE '^[[:space:]]*#[[:space:]]*include' "${sources[@]}" \
               --include='*.h' --include='*.hpp' --include='*.inl' --include='*.ipp' \
               --include='*.hh' --include='*.c' --include='*.cc' --include='*.cxx' --include='*.cpp' |
           sed "s#^$root/##")
resolved=""
computed=""
while IFS= read -r hit; do
    [ -n "$hit" ] || continue
    file=${hit%%:*}
    rest=${hit#*:}
    line=${rest%%:*}
    text=${rest#*:}
    if [[ $text =~ ^[[:space:]]*#[[:space:]]*include[[:space:]]*\<([^\>]+)\> ]]; then
        target=${BASH_REMATCH[1]}
    elif [[ $text =~ ^[[:space:]]*#[[:space:]]*include[[:space:]]*\"([^\"]+)\" ]]; then
        target=${BASH_REMATCH[1]}
        # A quoted include is searched next to its file first.
        if [ -e "$root/$(dirname "$file")/$target" ]; then
            target=$(realpath -m --relative-to="$root" "$root/$(dirname "$file")/$target")
        fi
    else
        computed+="$hit"$'\n'
        continue
    fi
    resolved+="$file:$line:$target"$'\n'
done <<<"$includes"
if [ -n "$computed" ]; then
    fail "an include this check cannot read (write it as #include <path> or \"path\"):" "$computed"
fi

# The includes of the files under $1/ whose target matches the extended regex $2.
includes_of() {
    grep -E "^$1/[^:]*:[0-9]+:($2)" <<<"$resolved" || true
}
check() {
    local layer="$1" pattern="$2" why="$3"
    local hits
    hits=$(includes_of "$layer" "($pattern)/")
    [ -z "$hits" ] || fail "$layer/ $why:" "$hits"
}
check pipeline 'hal|recordings|platform|state' \
    "must not depend on device, recording, state-stage or platform code"
check hal 'recordings|platform|state' "must not depend on recordings, state or platform"
check recordings 'platform|state' "must not depend on state or platform"
check state 'recordings|platform|pipeline/render' \
    "must not depend on recordings, platform or the renderer (hal -> state -> render)"
# hal and recordings may include only the header-only vocabulary from pipeline/base.
for layer in hal recordings; do
    hits=$(includes_of "$layer" 'pipeline/' | grep -vE ':pipeline/base/' || true)
    [ -z "$hits" ] || fail "$layer/ may include only pipeline/base/ from pipeline:" "$hits"
done
# The order inside pipeline/, lowest first (the same list heads pipeline/CMakeLists.txt).
order=(base csv colour spectral image brdf booth scene surface shading reference display tuning render offline)
declare -A rank
for i in "${!order[@]}"; do rank[${order[$i]}]=$i; done
for dir in "$root"/pipeline/*/; do
    folder=$(basename "$dir")
    if [ -z "${rank[$folder]+x}" ]; then
        fail "pipeline/$folder/ is not in the pipeline's order: add it to the list in \
tests/layering_check.sh and pipeline/CMakeLists.txt"
        continue
    fi
    while IFS= read -r hit; do
        [ -n "$hit" ] || continue
        target=${hit#*:*:pipeline/}
        target=${target%%/*}
        if [ -z "${rank[$target]+x}" ] || [ "${rank[$target]}" -gt "${rank[$folder]}" ]; then
            fail "pipeline/$folder/ may include only ${order[*]:0:${rank[$folder]}+1} (pipeline's order), not $target/: $hit"
        fi
    done < <(includes_of "pipeline/$folder" 'pipeline/')
done
# Only the renderer and the output may use GL, EGL, GBM or DRM: the CPU model, the reference, state
# and the devices build without them.
gl='(GLES[0-9]*|EGL|GL|KHR|drm|libdrm)/|(gbm|drm|drm_fourcc|drm_mode|xf86drm|xf86drmMode)\.h$'
hits=$(grep -E "^[^:]*:[0-9]+:($gl)" <<<"$resolved" | grep -vE '^(pipeline/render|platform/output)/' || true)
[ -z "$hits" ] || fail "only pipeline/render/ and platform/output/ may include GL, EGL, GBM or DRM headers:" "$hits"
# Offline tools (pipeline/offline/<area>/: fits, studies, generators) are for the CLI subcommands,
# benchmarks and tests: the run (the pipeline below offline/, state, the devices, the recorder, the
# loop, the output and the appliance) never includes them. pipeline/offline/ is last in the order,
# so that no other pipeline folder may include it; this says so in its own words and covers the
# other layers.
hits=$(grep -E '^[^:]*:[0-9]+:pipeline/offline/' <<<"$resolved" |
       grep -vE '^(pipeline/offline|platform/cli)/' || true)
[ -z "$hits" ] || fail "a run-time file includes an offline tool's header (pipeline/offline/ is for \
the CLI, benchmarks and tests; move the code the run needs out of the tool):" "$hits"
[ $status -eq 0 ] && echo "PASS: layer dependencies follow the allowed edges"
exit $status
