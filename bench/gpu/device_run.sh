#!/usr/bin/env bash
# Run on a GPU machine (bench/gpu/README.md), after unpacking the bundle into /tmp/g and the glvnd
# packages into /: the GL backend on the GPU against Embree on the same machine's CPUs, same VPLs.
# Writes logs and every report.json into $OUT/gpu_results.tar.gz.
set -uo pipefail
R=/tmp/g/results
source "$(dirname "$0")/device_env.sh"
nvidia-smi -L; nproc; uname -r
timeout 60 $G/bin/glcontext_test --gtest_brief=1 2>&1 | tail -15
$B samples $G/samples > /dev/null
bake cornell_auto 60 $B bake $G/samples/cornell_box.gltf
bake cornell_gl 60 $B bake $G/samples/cornell_box.gltf --backend gl
bake cornell_embree 60 $B bake $G/samples/cornell_box.gltf --backend embree
$B diff $R/cornell_embree $R/cornell_gl
SP="$S/dabrovic_sponza/sponza.glb --sun 0.35,-1,0.2,5 --sky 0.4,0.5,0.7"
for i in 1 2; do
  bake sponza_gl_$i 120 $B bake $SP --backend gl
  bake sponza_embree_$i 120 $B bake $SP --backend embree
done
$B diff $R/sponza_embree_1 $R/sponza_gl_1
# The CI-class machine's two cores with this GPU beside them.
for i in 1 2; do
  bake sponza_gl_2cpu_$i 150 taskset -c 0,1 $B bake $SP --backend gl --threads 2
  bake sponza_embree_2cpu_$i 150 taskset -c 0,1 $B bake $SP --backend embree --threads 2
done
# Larger VPL cubes are nearly free on a GPU: fewer texels the depth test cannot resolve.
bake sponza_gl_2cpu_cube256 150 taskset -c 0,1 $B bake $SP --backend gl --threads 2 --cube-face 256
SB="$S/sibenik/sibenik_lamp.glb --sky 1,1,1"
bake sibenik_gl 120 $B bake $SB --backend gl
bake sibenik_embree 120 $B bake $SB --backend embree
$B diff $R/sibenik_embree $R/sibenik_gl
( cd $G/src && timeout 150 $G/bin/gl_test --gtest_brief=1 ) > $R/gl_test.log 2>&1; echo "gl_test rc=$?"
grep -E "figure|FAILED|PASSED|SKIPPED|tests ran" $R/gl_test.log | head -40
nvidia-smi --query-gpu=name,driver_version,memory.used --format=csv
rm -f $R/*/*.exr $R/*/*.png $R/*/*.bin $R/*/*.glb
tar -C $G -czf $OUT/gpu_results.tar.gz results
