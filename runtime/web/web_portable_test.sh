#!/usr/bin/env bash
# The portable bake through optimisers: bake the Cornell box with --portable, run gltfpack on it (and
# `gltf-transform optimize` when @gltf-transform/cli is installed), render each result from its glTF camera
# with plain three.js (no MOZ_lightmap plugin) in headless Chromium and require a mean absolute difference
# ≤ 3 (8-bit) against irview's view of the normal bake; the Khronos validator finds no error in any of them
# (and no warning in the portable file).
# Usage (from ctest): web_portable_test.sh IRBAKE IRVIEW MODULES_DIR WORK_DIR
set -euo pipefail
irbake="$1" irview="$2" modules="$3" work="$4"
here="$(cd "$(dirname "$0")" && pwd)"
source "$here/web_tests_common.sh"
need_node_modules "$modules" gltfpack gltf-validator
need_browser_client "$modules" "$work"
bake_cornell_and_irview "$irbake" "$irview" "$work" --portable "$work/portable.glb"
node "$modules/node_modules/gltfpack/cli.js" -i "$work/portable.glb" -o "$work/packed.glb" > "$work/gltfpack.log" 2>&1
files=(portable packed)
cli="$modules/node_modules/@gltf-transform/cli/bin/cli.js"
if [[ -f "$cli" ]]; then
  node "$cli" optimize "$work/portable.glb" "$work/optimized.glb" > "$work/gltf-transform.log" 2>&1
  files+=(optimized)
else
  echo "note: $cli not installed: the gltf-transform optimize case is skipped"
fi
for f in "${files[@]}"; do
  echo "$f.glb: $(stat -c %s "$work/$f.glb") bytes"
  # The portable file: no error, no warning; an optimiser's output: no error and no warning the portable file lacks.
  if [[ $f == portable ]]; then node "$here/validate.mjs" --modules "$modules" --output "$work/$f.glb"
  else node "$here/validate.mjs" --modules "$modules" --output "$work/$f.glb" --input "$work/portable.glb"; fi
  node "$here/render_compare.mjs" --modules "$modules" --scene "$work/$f.glb" --camera 0 --width $w --height $h --plugin none \
    --reference "$work/irview.png" --out "$work/web_$f.png" --max-mean-abs 3
done
