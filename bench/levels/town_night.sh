#!/usr/bin/env bash
# docs/town_night.png: a 3x3-block night town (bench/levels/town.py: 24 street lamps with a range of 15 m, a
# dim night sky) baked at --quality preview and drawn by irview from the town's camera (exposure -1), down a
# street where the lamps' pools of light overlap and end. From the repository root after a Release build:
#   bash bench/levels/town_night.sh [IRBAKE] [IRVIEW]
set -euo pipefail
IRBAKE=${1:-build/baker/irbake}
IRVIEW=${2:-build/runtime/irview}
W=build/levels/town_night
mkdir -p $W
python3 bench/levels/town.py $W/town3_night.glb --blocks 3 --lamps 24 --range 15 --camera=-22,9,-84,-26,1,-20
"$IRBAKE" bake $W/town3_night.glb -o $W/out --quality preview --sky 0.02,0.03,0.06 --probes off --quiet
"$IRVIEW" $W/out/scene.gltf --camera 0 --width 960 --height 540 --exposure -1 --screenshot docs/town_night.png
