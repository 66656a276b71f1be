#!/usr/bin/env bash
# README command (a): install what is missing, build, write the sample scenes and bake the Cornell
# box into out/ (default backend: GL on EGL; extra options are passed on, e.g. --backend embree).
# Usage: scripts/bake-sample.sh [extra irbake bake options]
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
bash scripts/build.sh
mkdir -p out/samples
./build/baker/irbake samples out/samples
# About 250k texels and 1536 light paths: ≈ 1.9% relative RMSE against a converged reference
# (docs/performance.md).
./build/baker/irbake bake out/samples/cornell_box.gltf -o out --texels-per-unit 360 --vpls 1536 "$@"
echo
echo "glTF with MOZ_lightmap: $(pwd)/out/scene.gltf"
echo "float EXR pages:        $(ls "$(pwd)"/out/lightmap_*.exr | tr '\n' ' ')"
echo "report:                 $(pwd)/out/report.json"
