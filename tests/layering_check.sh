#!/usr/bin/env bash
# Checks the allowed dependency edges between layers (style guide section 1): pipeline and hal include
# nothing of the other layers (hal may use pipeline/base only); recordings only hal and pipeline/base;
# state/ (sensor samples -> SceneState) sits between hal and the renderer: it may include hal and the
# pipeline below render/, and nothing but platform includes it (hal -> state -> render).
# Inside pipeline/, its folders are in an order (pipeline/CMakeLists.txt): each may include only itself
# and the folders before it; only render/ includes GL headers; no run-time file includes the header of
# an offline tool (the list in pipeline/CMakeLists.txt).
set -uo pipefail
root="$1"
status=0
check() {
    local layer="$1" pattern="$2" why="$3"
    local hits
    hits=$(grep -rnE "#include <($pattern)/" "$root/$layer" --include='*.h' --include='*.cpp' || true)
    if [ -n "$hits" ]; then
        echo "FAIL: $layer/ $why:" >&2
        echo "$hits" >&2
        status=1
    fi
}
check pipeline 'hal|recordings|platform|state' \
    "must not depend on device, recording, state-stage or platform code"
check hal 'recordings|platform|state' "must not depend on recordings, state or platform"
check recordings 'platform|state' "must not depend on state or platform"
check state 'recordings|platform|pipeline/render' \
    "must not depend on recordings, platform or the renderer (hal -> state -> render)"
# hal may include only the header-only vocabulary from pipeline/base.
hits=$(grep -rnE '#include <pipeline/' "$root/hal" --include='*.h' --include='*.cpp' | grep -v '<pipeline/base/' || true)
if [ -n "$hits" ]; then
    echo "FAIL: hal/ may include only pipeline/base/ from pipeline:" >&2
    echo "$hits" >&2
    status=1
fi
hits=$(grep -rnE '#include <pipeline/' "$root/recordings" --include='*.h' --include='*.cpp' | grep -v '<pipeline/base/' || true)
if [ -n "$hits" ]; then
    echo "FAIL: recordings/ may include only pipeline/base/ from pipeline:" >&2
    echo "$hits" >&2
    status=1
fi
# The order inside pipeline/, lowest first (the same list heads pipeline/CMakeLists.txt).
order=(base csv colour spectral image brdf booth scene surface shading reference display tuning render)
declare -A rank
for i in "${!order[@]}"; do rank[${order[$i]}]=$i; done
for dir in "$root"/pipeline/*/; do
    folder=$(basename "$dir")
    if [ -z "${rank[$folder]+x}" ]; then
        echo "FAIL: pipeline/$folder/ is not in the pipeline's order: add it to the list in" \
             "tests/layering_check.sh and pipeline/CMakeLists.txt" >&2
        status=1
        continue
    fi
    while IFS= read -r hit; do
        [ -n "$hit" ] || continue
        target=$(sed -E 's#.*<pipeline/([a-z_]+)/.*#\1#' <<<"$hit")
        if [ -z "${rank[$target]+x}" ] || [ "${rank[$target]}" -gt "${rank[$folder]}" ]; then
            echo "FAIL: pipeline/$folder/ may include only ${order[*]:0:${rank[$folder]}+1}" \
                 "(pipeline's order), not $target/: ${hit#"$root"/}" >&2
            status=1
        fi
    done < <(grep -rnE '#include <pipeline/' "$dir" --include='*.h' --include='*.cpp' || true)
done
# Only render/ may use GL: the CPU model and the reference build without GLES.
hits=$(grep -rnE '#include <(GLES[0-9]*|EGL|GL)/' "$root/pipeline" --include='*.h' --include='*.cpp' |
       grep -v "^$root/pipeline/render/" || true)
if [ -n "$hits" ]; then
    echo "FAIL: only pipeline/render/ may include GL headers:" >&2
    echo "$hits" >&2
    status=1
fi
# Offline tools (fits, studies, generators) are for the CLI, benchmarks and tests: no run-time file
# of the pipeline includes their headers.
offline=$(sed -n '/# offline-sources-begin/,/# offline-sources-end/p' "$root/pipeline/CMakeLists.txt" |
          grep -oE '[a-z_]+/[a-z_0-9]+\.cpp' | sed 's/\.cpp$//')
if [ -z "$offline" ]; then
    echo "FAIL: no offline-sources list found in pipeline/CMakeLists.txt" >&2
    status=1
fi
for tool in $offline; do
    while IFS= read -r hit; do
        [ -n "$hit" ] || continue
        file=$(cut -d: -f1 <<<"$hit")
        rel=${file#"$root"/pipeline/}
        rel=${rel%.*}
        # The tool's own files and the other offline tools may include it.
        if ! grep -qxF "$rel" <<<"$offline"; then
            echo "FAIL: run-time pipeline file includes an offline tool's header (move the file to" \
                 "the offline list in pipeline/CMakeLists.txt, or the code out of the tool):" \
                 "${hit#"$root"/}" >&2
            status=1
        fi
    done < <(grep -rnF "#include <pipeline/$tool.h>" "$root/pipeline" --include='*.h' --include='*.cpp' || true)
done
[ $status -eq 0 ] && echo "PASS: layer dependencies follow the allowed edges"
exit $status
