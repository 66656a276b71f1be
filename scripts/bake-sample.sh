#!/usr/bin/env bash
# README command (a): install what is missing, build, write the sample scenes and bake the Cornell
# box into out/ (default backend auto: GL on EGL for this small scene; extra options are passed on, e.g.
# --backend embree).
# Usage: scripts/bake-sample.sh [extra irbake bake options]
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
bash scripts/build.sh
mkdir -p out/samples
./build/baker/irbake samples out/samples
# Default options (--quality default; `--dump-config FILE` writes them out); the bake's error against
# Blender Cycles baked into the same atlas is in docs/validation.md, "Cornell boxes".
./build/baker/irbake bake out/samples/cornell_box.gltf -o out "$@"
echo
echo "glTF with MOZ_lightmap: $(pwd)/out/scene.gltf"
echo "float EXR pages:        $(ls "$(pwd)"/out/lightmap_*.exr | tr '\n' ' ')"
echo "report:                 $(pwd)/out/report.json"
