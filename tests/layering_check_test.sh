#!/usr/bin/env bash
# Shows tests/layering_check.sh failing on one planted violation of the given kind:
#   layering_check_test.sh SOURCE_ROOT KIND
# It builds a minimal tree in a temporary folder (the layers' folders, the pipeline's folders and a
# CLI file that includes an offline tool), asserts the check passes on it, plants the
# violation, and asserts the check then fails with the expected message naming the planted file.
set -uo pipefail
src="$1"
kind="$2"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
for layer in hal pipeline platform recordings state tests; do mkdir -p "$tmp/$layer"; done
for folder in base csv colour spectral image brdf booth scene surface shading reference display tuning render \
              offline/display; do
    mkdir -p "$tmp/pipeline/$folder"
done
# The CLI may include an offline tool (its subcommands run them): the minimal tree does.
mkdir -p "$tmp/platform/cli"
printf '#include <pipeline/offline/display/display_fit.h>\n' >"$tmp/platform/cli/fit_command.cpp"

if ! bash "$src/tests/layering_check.sh" "$tmp" >/dev/null 2>"$tmp.err"; then
    echo "FAIL: the minimal tree fails the check before anything is planted:" >&2
    cat "$tmp.err" >&2
    rm -f "$tmp.err"
    exit 1
fi
rm -f "$tmp.err"

# plant FILE LINE...: writes the lines into FILE under the tree.
plant() {
    local file="$1"
    shift
    mkdir -p "$(dirname "$tmp/$file")"
    printf '%s\n' "$@" >"$tmp/$file"
}
# An offline tool: any header under pipeline/offline/.
offline_tool=offline/display/display_fit
expect=()
case "$kind" in
quoted)
    plant pipeline/colour/planted.cpp '#include "platform/appliance.h"'
    expect=("pipeline/ must not depend" "pipeline/colour/planted.cpp:1:platform/appliance.h") ;;
quoted_relative)
    plant pipeline/render/renderer.h '#pragma once'
    plant pipeline/colour/planted.cpp '#include "../render/renderer.h"'
    expect=("pipeline/colour/ may include only" "not render/" "pipeline/colour/planted.cpp:1:pipeline/render/renderer.h") ;;
hash_space)
    plant pipeline/brdf/planted.cpp '  # include <hal/samples.h>'
    expect=("pipeline/ must not depend" "pipeline/brdf/planted.cpp:1:hal/samples.h") ;;
include_spaces)
    plant recordings/planted.cpp '#include   <platform/appliance.h>'
    expect=("recordings/ must not depend" "recordings/planted.cpp:1:platform/appliance.h") ;;
hpp)
    plant pipeline/base/planted.hpp '#include <pipeline/render/renderer.h>'
    expect=("pipeline/base/ may include only" "pipeline/base/planted.hpp:1:pipeline/render/renderer.h") ;;
inl)
    plant state/planted.inl '#include <recordings/recording.h>'
    expect=("state/ must not depend" "state/planted.inl:1:recordings/recording.h") ;;
gl)
    plant pipeline/display/planted.cpp '#include <GLES3/gl31.h>'
    plant state/planted.cpp '#include <EGL/egl.h>'
    expect=("only pipeline/render/ and platform/output/ may include GL"
            "pipeline/display/planted.cpp:1:GLES3/gl31.h" "state/planted.cpp:1:EGL/egl.h") ;;
gbm_drm)
    plant hal/planted.cpp '#include <gbm.h>'
    plant platform/loop/planted.cpp '#include <xf86drmMode.h>' '#include <drm/drm_fourcc.h>'
    expect=("only pipeline/render/ and platform/output/ may include GL" "hal/planted.cpp:1:gbm.h"
            "platform/loop/planted.cpp:1:xf86drmMode.h" "platform/loop/planted.cpp:2:drm/drm_fourcc.h") ;;
state_offline)
    plant state/planted.cpp "#include <pipeline/$offline_tool.h>"
    expect=("includes an offline tool's header" "state/planted.cpp:1:pipeline/$offline_tool.h") ;;
pipeline_offline)
    plant pipeline/render/planted.cpp "#include <pipeline/$offline_tool.h>"
    expect=("includes an offline tool's header" "pipeline/render/planted.cpp:1:pipeline/$offline_tool.h") ;;
platform_offline)
    plant platform/loop/planted.cpp "#include <pipeline/$offline_tool.h>"
    expect=("includes an offline tool's header" "platform/loop/planted.cpp:1:pipeline/$offline_tool.h") ;;
top_folder)
    mkdir -p "$tmp/plugins"
    plant plugins/planted.cpp '#include <pipeline/render/renderer.h>'
    expect=("plugins/ is a top-level folder this check does not know") ;;
pipeline_folder)
    mkdir -p "$tmp/pipeline/extras"
    expect=("pipeline/extras/ is not in the pipeline's order") ;;
computed)
    plant pipeline/colour/planted.cpp '#include PLANTED_HEADER'
    expect=("an include this check cannot read" "pipeline/colour/planted.cpp:1:#include PLANTED_HEADER") ;;
*)
    echo "unknown kind '$kind'" >&2
    exit 2 ;;
esac

out=$(bash "$src/tests/layering_check.sh" "$tmp" 2>&1)
rc=$?
if [ $rc -eq 0 ]; then
    echo "FAIL: the layering check passed a planted '$kind' violation:" >&2
    echo "$out" >&2
    exit 1
fi
for message in "${expect[@]}"; do
    if ! grep -qF -- "$message" <<<"$out"; then
        echo "FAIL: the layering check failed on the planted '$kind' violation without saying '$message':" >&2
        echo "$out" >&2
        exit 1
    fi
done
echo "PASS: the layering check fails on a planted '$kind' violation"
