#!/usr/bin/env bash
# The same scene baked plain and after glTF-Transform's meshopt, draco and quantize (its CLI from
# BUILD/web/node_modules; skipped, exit 77, when absent) gives the same maps: `irbake diff` of each
# variant's bake against the plain bake (relative RMSE, texel-wise on the atlas) within MAX_RMSE, and
# irview's headless screenshots of each variant's input (albedo view) and of its bake match the plain
# ones within MAX_MAD of 255; each variant's export passes the Khronos validator (runtime/web/validate.mjs).
# Prints one CSV row per variant; with CSV set, appends them there too (bench/results/compressed_inputs.csv).
# MESHOPT: the glTF-Transform command of the meshopt variant (default "meshopt"; "optimize --simplify false"
# is the README's whole optimiser). VIEW: irview's view (default camera 0, else its overview).
# ATLAS_MAY_DIFFER=1: see below.
# Usage: compressed_inputs_test.sh IRBAKE IRVIEW GLTF_TRANSFORM WORKDIR [SCENE [NAME [BAKE_ARGS...]]]
set -euo pipefail
irbake=$1 irview=$2 gt=$3 work=$4
scene=${5:-} name=${6:-cornell_box}
shift $(( $# < 6 ? $# : 6 ))
max_rmse=${MAX_RMSE:-0.02} max_mad=${MAX_MAD:-2.0}
if [[ ! -x "$gt" ]]; then
  echo "SKIPPED: glTF-Transform CLI not found at $gt (scripts/install-web-deps.sh installs it)"
  exit 77
fi
modules=$(dirname "$(dirname "$gt")")  # BUILD/web/node_modules
validate=$(cd "$(dirname "$0")/../../runtime/web" && pwd)/validate.mjs
rm -rf "$work" && mkdir -p "$work"
if [[ -z "$scene" ]]; then
  "$irbake" samples "$work/samples" >/dev/null
  scene=$work/samples/cornell_box.gltf
elif [[ ! -f "$scene" ]]; then
  echo "SKIPPED: $scene not found"
  exit 77
fi
# shellcheck disable=SC2086  # MESHOPT is a command and its options
"$gt" ${MESHOPT:-meshopt} "$scene" "$work/meshopt.glb" >"$work/gt_meshopt.log" 2>&1
"$gt" draco "$scene" "$work/draco.glb" >"$work/gt_draco.log" 2>&1
"$gt" quantize "$scene" "$work/quantize.glb" >"$work/gt_quantize.log" 2>&1

# Mean absolute difference of two PNGs, in units of 1/255 (OpenImageIO's idiff: mean error over 0..1; it
# prints none, only PASS, for identical images, and exits non-zero when they differ).
mad() { { idiff -abs "$1" "$2" 2>/dev/null || true; } | awk '/Mean error/ {m = $4} END {printf "%.3f", m * 255}'; }

shot() {  # shot SCENE OUT.png [irview args]: headless screenshot from camera 0, or the overview
  local in=$1 out=$2; shift 2
  # shellcheck disable=SC2086  # VIEW: irview's view options, e.g. "--eye X,Y,Z --target X,Y,Z"
  "$irview" "$in" --width 256 --height 256 --screenshot "$out" ${VIEW:-} "$@" >"$out.log" 2>&1 || { cat "$out.log"; return 1; }
}

# validate VARIANT INPUT: the Khronos validator on the variant's export; prints its error count.
validate_export() {
  node "$validate" --modules "$modules" --output "$work/bake_$1/scene.gltf" --input "$2" >"$work/validate_$1.log" 2>&1 || true
  python3 -c 'import json,sys; print(json.loads(sys.stdin.readline())["errors"])' <"$work/validate_$1.log" 2>/dev/null || echo 999999
}
can_validate=0
command -v node >/dev/null && [[ -d "$modules" ]] && can_validate=1

fail=0
echo "date,scene,variant,options,relative_rmse,mean_bias,input_mad,bake_mad"
for variant in plain meshopt draco quantize; do
  in=$scene
  [[ $variant != plain ]] && in=$work/$variant.glb
  "$irbake" bake "$in" -o "$work/bake_$variant" --quiet "$@" >"$work/bake_$variant.log" 2>&1 || { cat "$work/bake_$variant.log"; fail=1; continue; }
  shot "$in" "$work/input_$variant.png" --view albedo || { fail=1; continue; }
  shot "$work/bake_$variant/scene.gltf" "$work/bake_$variant.png" || { fail=1; continue; }
  # What the export wrote back (the decoded document) validates as the plain input's export does (a
  # third-party input may bring errors of its own, e.g. a mimeType 'image/JPG').
  if [[ $can_validate == 1 ]]; then
    errors=$(validate_export "$variant" "$in")
    [[ $variant == plain ]] && plain_errors=$errors
    if [[ $variant != plain ]] && ((errors > plain_errors)); then
      echo "FAIL: $variant: the export has $errors validator errors, the plain one $plain_errors"; cat "$work/validate_$variant.log"; fail=1
    fi
  fi
  [[ $variant == plain ]] && continue
  if [[ $variant != quantize ]] && ! grep -q '"decodedExtensions"' "$work/bake_$variant/report.json"; then
    echo "FAIL: $variant: report.json does not list the decoded extension"; fail=1
  fi
  input_mad=$(mad "$work/input_$variant.png" "$work/input_plain.png")
  bake_mad=$(mad "$work/bake_$variant.png" "$work/bake_plain.png")
  # irbake diff compares texel by texel on one atlas. Quantised positions can change a large scene's
  # chart sizes and so its atlas: with ATLAS_MAY_DIFFER=1 that is recorded (no figure) and the
  # screenshots of the bakes compare the maps in scene space instead.
  rmse="" bias=""
  if figures=$("$irbake" diff "$work/bake_$variant" "$work/bake_plain" --json 2>&1); then
    rmse=$(python3 -c 'import json,sys; print("%.5f" % json.loads(sys.stdin.read())["relativeRmse"])' <<<"$figures")
    bias=$(python3 -c 'import json,sys; print("%.5f" % json.loads(sys.stdin.read())["relativeBias"])' <<<"$figures")
  elif [[ "${ATLAS_MAY_DIFFER:-0}" != 1 || $figures != *"not the same atlas"* ]]; then
    echo "FAIL: $variant: $figures"; fail=1; continue
  fi
  row="$(date -u +%Y-%m-%d),$name,$variant,\"$*\",$rmse,$bias,$input_mad,$bake_mad"
  echo "$row"
  [[ -n "${CSV:-}" ]] && echo "$row" >>"$CSV"
  if ! python3 -c "import sys; sys.exit(0 if ('$rmse' == '' or $rmse <= $max_rmse) and $input_mad <= $max_mad and $bake_mad <= $max_mad else 1)"; then
    echo "FAIL: $variant: relative RMSE $rmse (at most $max_rmse), MAD $input_mad / $bake_mad of 255 (at most $max_mad)"; fail=1
  fi
done
exit $fail
