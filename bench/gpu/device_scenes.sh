#!/usr/bin/env bash
# Run on a GPU machine after device_run.sh's set-up (bench/gpu/README.md): GL against Embree on scenes
# of other sizes and at other CPU counts, to place --backend auto's rule on a hardware renderer.
# Writes logs and every report.json into $OUT/gpu_scenes.tar.gz.
set -uo pipefail
R=/tmp/g/results_scenes
source "$(dirname "$0")/device_env.sh"
pair() {  # tag threads args...
  local tag=$1 th=$2; shift 2
  local cpus=0-$((th - 1))
  bake ${tag}_gl_$th 150 taskset -c $cpus $B bake "$@" --backend gl --threads $th
  bake ${tag}_embree_$th 150 taskset -c $cpus $B bake "$@" --backend embree --threads $th
}
HE="$S/damaged_helmet/DamagedHelmet.gltf --sky 0.5,0.5,0.5"
BU="$S/stanford_bunny/bunny.glb --sun 0.35,-1,0.2,5 --sky 0.4,0.5,0.7"
MC="$S/mcguire/mcguire_cornell.gltf"
SP="$S/dabrovic_sponza/sponza.glb --sun 0.35,-1,0.2,5 --sky 0.4,0.5,0.7"
for th in 16 2; do pair mcguire $th $MC; pair helmet $th $HE; pair bunny $th $BU; done
pair sponza 4 $SP
bake sponza_gl_2_cube512 150 taskset -c 0,1 $B bake $SP --backend gl --threads 2 --cube-face 512
bake sponza_auto 150 $B bake $SP
bake helmet_auto 150 $B bake $HE
rm -f $R/*/*.exr $R/*/*.png $R/*/*.bin $R/*/*.glb
tar -C $G -czf $OUT/gpu_scenes.tar.gz results_scenes
