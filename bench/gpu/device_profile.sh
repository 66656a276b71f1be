#!/usr/bin/env bash
# Run on a GPU machine after device_run.sh's set-up (bench/gpu/README.md): every stage's wall time of
# the default bake (Cornell, Sponza sun + sky, Sibenik sky + lamp) with the GL backend and with Embree, the
# GPU memory peak of each bake (nvidia-smi sampled every 50 ms), and Sponza with more VPLs in place of the
# final gather. Writes logs and every report.json into $OUT/gpu_profile_<label>.tar.gz.
#   bash bench/gpu/device_profile.sh LABEL [IRBAKE]
set -uo pipefail
LABEL=${1:-run}
R=/tmp/g/profile_$LABEL
source "$(dirname "$0")/device_env.sh"
B=${2:-$B}
# tag timeout command...: bake() with the GPU memory peak (MiB, the whole device) beside it.
gbake() {
  local tag=$1
  nvidia-smi --query-gpu=memory.used --format=csv,noheader,nounits -lms 50 > $R/$tag.gpumem 2>/dev/null &
  local smi=$!
  bake "$@" | tee -a $R/walls.txt
  kill $smi 2>/dev/null; wait $smi 2>/dev/null
  echo "$tag gpu_mem_peak_mib=$(sort -n $R/$tag.gpumem | tail -1)" | tee -a $R/gpumem.txt
}
$B samples $G/samples > /dev/null
CO="$G/samples/cornell_box.gltf"
SP="$S/dabrovic_sponza/sponza.glb --sun 0.35,-1,0.2,5 --sky 0.4,0.5,0.7"
SB="$S/sibenik/sibenik_lamp.glb --sky 1,1,1"
echo "idle gpu_mem_mib=$(nvidia-smi --query-gpu=memory.used --format=csv,noheader,nounits)" | tee $R/gpumem.txt
for i in 1 2 3; do
  gbake cornell_gl_$i 60 $B bake $CO --backend gl --gpu-timers
  gbake sponza_gl_$i 120 $B bake $SP --backend gl --gpu-timers
done
gbake cornell_embree_1 60 $B bake $CO --backend embree
gbake sponza_embree_1 120 $B bake $SP --backend embree
gbake sponza_auto_1 120 $B bake $SP
for i in 1 2; do gbake sibenik_gl_$i 120 $B bake $SB --backend gl --gpu-timers; done
gbake sibenik_embree_1 120 $B bake $SB --backend embree
${PROFILE_EXTRA:-true}
rm -f $R/*/*.exr $R/*/*.png $R/*/*.bin $R/*/*.glb $R/*/*.jpg $R/*/*.gltf
tar -C $G -czf $OUT/gpu_profile_$LABEL.tar.gz profile_$LABEL
