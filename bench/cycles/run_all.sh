#!/usr/bin/env bash
# The whole comparison against Blender Cycles (docs/validation.md, "Accuracy against Cycles").
# From the repository root, after a Release build:  bash bench/cycles/run_all.sh [IRBAKE [IRVIEW]]
# Cycles results are cached under build/cycles-cache (by input checksum): a re-run after a baker change
# re-runs our bakes and re-bakes Cycles' maps only if our atlas changed. Rows are appended to
# bench/results/cycles_<scene>.csv. A cold run takes hours on a 2-core machine, most of it in Sponza's 8192-spp views and Cycles' ladder.
set -euo pipefail
IRBAKE=${1:-build/baker/irbake}
IRVIEW=${2:-build/runtime/irview}
C=(nice -n 15 /usr/bin/python3 bench/cycles/compare.py --irbake "$IRBAKE" --irview "$IRVIEW")
S=build/cycles-scenes
/usr/bin/python3 bench/cycles/scenes.py all $S
nice -n 15 "$IRBAKE" samples $S/samples
CORNELL=$S/samples/cornell_box.gltf
MCGUIRE=$S/mcguire_cornell.gltf
SPONZA=$S/sponza_sun_x4.glb  # textures upsampled 4x: Cycles filters them in sRGB space (docs/validation.md)
"${C[@]}" $CORNELL --name cornell_sample --opts "" --opts "--vpls 4096" --maps --map-spp 256 --map-ladder 4,16,64 \
    --views 0 --view-size 128x128 --view-spp 2048 --save-diff
"${C[@]}" $MCGUIRE --name mcguire_cornell --opts "" --opts "--vpls 4096" --maps --map-spp 256 --map-ladder 4,16,64 \
    --views 0 --view-size 128x128 --view-spp 2048 --save-diff
"${C[@]}" $SPONZA --name sponza_sun_x4 --opts "" --opts "--seed 1" --opts "--seed 2" --views 3,0,1,2 --view-size 160x100 \
    --view-spp 8192 --save-diff
# Sponza's map against Cycles' own bake (the sun kept: cycles_bake_lights.py), its ladder up to our error.
"${C[@]}" $SPONZA --name sponza_sun_x4 --opts "" --maps --bake-lights --map-spp 256 --map-ladder 4,16,64,96 --save-diff
# Sponza with the sun and a sky, each --quality preset (the default's rows are the table's sun + sky rows):
# views 0-2 against 1024 spp, the gallery (view 3) against 8192 spp.
for views in "0,1,2 1024" "3 8192"; do
  set -- $views
  "${C[@]}" $S/sponza_sun.glb --name sponza_sun_sky --sky 0.4,0.5,0.7 --opts "--sky 0.4,0.5,0.7 --quality preview" \
      --opts "--sky 0.4,0.5,0.7" --opts "--sky 0.4,0.5,0.7 --quality high" --opts "--sky 0.4,0.5,0.7 --quality production" \
      --views "$1" --view-size 160x100 --view-spp "$2" --save-diff
done
# Sibenik lit by its interior lamp alone (glass made opaque: scenes.py); no emitters, so no emitter cut.
"${C[@]}" $S/sibenik/sibenik_lamp.glb --name sibenik_lamp --opts "" --views 0,1,2,3,4,5 --view-size 160x100 --view-spp 1024 \
    --emitter-cut 1e30 --save-diff
# Irradiance probes: a white sphere at three places in the McGuire box and in Sponza sun + sky.
P=(nice -n 15 /usr/bin/python3 bench/cycles/probe_spheres.py --irbake "$IRBAKE" --irview "$IRVIEW")
"${P[@]}" --seeds 0,1,2
"${P[@]}" --seeds 0 --spp 512 --cycles-sphere camera
"${P[@]}" --scenes sponza --seeds 0 --bake-opts "--probes 1"
"${P[@]}" --scenes cornell --seeds 0,1,2 --bake-opts "--probe-rays 16384"
"${P[@]}" --scenes cornell --seeds 0 --bake-opts "--probes 0.1"
/usr/bin/python3 bench/cycles/table.py bench/results/cycles_*.csv
