#!/usr/bin/env bash
# irview on a gltfpack'd portable GLB: bakes SCENE with --portable, runs gltfpack with its defaults (quantised
# attributes with KHR_mesh_quantization, UVs dequantised by KHR_texture_transform, meshes merged), renders both
# GLBs headless with irview from the same view and prints their mean absolute difference (8-bit, RGB). With
# LIMIT it fails (exit 1) above it; with CSV it appends a row there.
# usage: irview_gltfpack.sh IRBAKE IRVIEW MODULES_DIR WORK SCENE LIMIT|- CSV|- [bake options...]
#   SCENE: a glTF file, or samples:NAME for a sample scene (`irbake samples`, written into WORK).
#   MODULES_DIR holds node_modules/gltfpack (scripts/install-web-deps.sh); VIEW (environment) gives irview's
#   view options (default: --camera 0).
set -euo pipefail
irbake="$1" irview="$2" modules="$3" work="$4" scene="$5" limit="$6" csv="$7"; shift 7
gltfpack="$modules/node_modules/gltfpack/cli.js"
command -v node >/dev/null 2>&1 || { echo "SKIPPED: node not found"; exit 77; }
[[ -f "$gltfpack" ]] || { echo "SKIPPED: $gltfpack missing (run scripts/install-web-deps.sh BUILD_DIR)"; exit 77; }
command -v oiiotool >/dev/null 2>&1 || { echo "SKIPPED: oiiotool not found (openimageio-tools)"; exit 77; }
rm -rf "$work" && mkdir -p "$work"
view=(${VIEW:---camera 0})
if [[ "$scene" == samples:* ]]; then
  "$irbake" samples "$work/samples" --quiet > "$work/samples.log" 2>&1
  scene="$work/samples/${scene#samples:}.gltf"
fi
start=$(date +%s)
"$irbake" bake "$scene" -o "$work/bake" --portable "$work/portable.glb" "$@" --quiet > "$work/bake.log" 2>&1 ||
  { cat "$work/bake.log"; exit 1; }
bake_s=$(( $(date +%s) - start ))
node "$gltfpack" -i "$work/portable.glb" -o "$work/packed.glb" > "$work/gltfpack.log" 2>&1 || { cat "$work/gltfpack.log"; exit 1; }
for f in portable packed; do
  "$irview" "$work/$f.glb" "${view[@]}" --width 320 --height 320 --screenshot "$work/$f.png" > "$work/irview_$f.log" 2>&1 ||
    { echo "irview failed on $f.glb:"; cat "$work/irview_$f.log"; exit 1; }
done
# irview must apply or name what gltfpack wrote, never render it silently wrong.
if grep -q "KHR_texture_transform\|KHR_mesh_quantization" "$work/irview_packed.log"; then
  echo "irview warned on the packed file:"; cat "$work/irview_packed.log"; exit 1
fi
mean=$( (oiiotool "$work/packed.png" --ch R,G,B "$work/portable.png" --ch R,G,B --diff 2>&1 || true) | sed -n "s/.*Mean error = *//p" | head -1)
[[ -n "$mean" ]] || { echo "oiiotool gave no mean error"; exit 1; }
mad=$(awk -v m="$mean" 'BEGIN { printf "%.3f", m * 255 }')
portable_bytes=$(stat -c %s "$work/portable.glb") packed_bytes=$(stat -c %s "$work/packed.glb")
echo "irview, gltfpack'd portable GLB against the portable GLB: mean absolute difference $mad of 255" \
     "(portable $portable_bytes B, packed $packed_bytes B, bake ${bake_s} s)"
if [[ "$csv" != "-" ]]; then
  [[ -f "$csv" ]] || echo "date,scene,bake_options,view,portable_bytes,packed_bytes,mean_abs_diff_255,bake_seconds" > "$csv"
  echo "$(date -u +%Y-%m-%d),$(basename "$scene"),\"$*\",\"${view[*]}\",$portable_bytes,$packed_bytes,$mad,$bake_s" >> "$csv"
fi
if [[ "$limit" != "-" ]] && awk -v d="$mad" -v l="$limit" 'BEGIN { exit !(d > l) }'; then
  echo "FAIL: $mad > $limit"; exit 1
fi
