#!/usr/bin/env bash
# The preflight against the bake on the level sizes: bakes the calibration levels (bench/levels/cost_bakes.py,
# into build/calibration; a folder with a measured.json is kept, REBAKE=1 bakes again), then appends to
# bench/results/plan_accuracy.csv one row per bake: the binary's `plan --json` prediction against the measured
# CPU seconds and peak memory, their ratios, the idle machine's wall time the CPU time implies, the plan's own
# time and the load average. The machine is shared, so the CPU time is compared and the wall time recorded.
# The bakes: the sample box, Sponza, small towns at several densities, and the level ladder's towns
# (bench/levels/levels_scale.sh's scenes and densities: town4, town8, the 16x16 town's 1,000 lamps with and
# without range at --quality preview; LARGE=1 adds town32 with 2,000 lamps). From the repository root after a
# Release build:
#   HOLD_OUT=sponza_sunsky_preview,town16_lamps_range,town8_lamps,town8_sunsky_tpu3_preview LARGE=1 \
#     bash bench/levels/plan_accuracy.sh [IRBAKE]
# HOLD_OUT names the runs left out of the fit (fit_cost_model.py --hold-out, the same names); LEVELS_CSV adds a
# level ladder's CSV rows (measured with the binary that wrote them), LEVELS_COMMIT only those of one commit.
set -euo pipefail
IRBAKE=${1:-build/baker/irbake}
W=build/calibration
SHARED=../shared/scenes
SUN="--sun 0.35,-1,0.2,5"
SKY="--sky 0.4,0.5,0.7"
mkdir -p $W build/levels
bake() {  # name scene options...
  local name=$1 scene=$2; shift 2
  [[ -f $scene ]] || { echo "plan_accuracy: $scene not found, skipped"; return 0; }
  [[ -f $W/$name/measured.json && ${REBAKE:-0} != 1 ]] || python3 bench/levels/cost_bakes.py "$IRBAKE" $W "$name" "$scene" "$@"
}
[[ -f build/levels/town4.glb ]] || python3 bench/levels/town.py build/levels/town4.glb --blocks 4 --lamps 32 --cell 2.2
[[ -f build/levels/town6.glb ]] || python3 bench/levels/town.py build/levels/town6.glb --blocks 6 --lamps 64
[[ -f build/levels/town8.glb ]] || python3 bench/levels/town.py build/levels/town8.glb --blocks 8 --lamps 128
[[ -f build/scenes/cornell_box.gltf ]] || "$IRBAKE" samples build/scenes --quiet
bake cornell_default build/scenes/cornell_box.gltf
bake cornell_preview build/scenes/cornell_box.gltf --quality preview
bake town4_sunsky_tpu4 build/levels/town4.glb $SUN $SKY --texels-per-unit 4
bake town4_sun_tpu6 build/levels/town4.glb $SUN --texels-per-unit 6
bake town6_sun_tpu5_preview build/levels/town6.glb $SUN --texels-per-unit 5 --quality preview
bake town8_sunsky_tpu3_preview build/levels/town8.glb $SUN $SKY --texels-per-unit 3 --quality preview
bake sponza_sun $SHARED/dabrovic_sponza/sponza.glb $SUN
bake sponza_sunsky_preview $SHARED/dabrovic_sponza/sponza.glb $SUN $SKY --quality preview
town() {  # file town.py options...: the ladder's scene, made once
  local file=build/levels/$1; shift
  [[ -f $file ]] || python3 bench/levels/town.py "$file" "$@" > /dev/null
  echo "$file"
}
bake town4_lamps "$(town ladder_town4.glb --blocks 4 --lamps 32)" $SUN $SKY --texels-per-unit 2.61
bake town8_lamps "$(town ladder_town8.glb --blocks 8 --lamps 128)" $SUN $SKY --texels-per-unit 2.09
bake town16_lamps_range "$(town ladder_lamps_range.glb --blocks 16 --lamps 1000)" $SUN $SKY --quality preview \
  --texels-per-unit 1.331
bake town16_lamps_norange "$(town ladder_lamps_norange.glb --blocks 16 --lamps 1000 --range 0)" $SUN $SKY \
  --quality preview --texels-per-unit 1.331
if [[ ${LARGE:-0} == 1 ]]; then
  bake town32_lamps "$(town ladder_town32.glb --blocks 32 --lamps 2000 --cell 2.2)" $SUN $SKY --quality preview \
    --texels-per-unit 0.67
fi
LEVELS=()
[[ -n ${LEVELS_CSV:-} ]] && LEVELS=(--levels "$LEVELS_CSV" --levels-commit "${LEVELS_COMMIT:-}")
python3 bench/levels/fit_cost_model.py "$IRBAKE" $W/*/ "${LEVELS[@]}" --hold-out "${HOLD_OUT:-}" \
  --accuracy bench/results/plan_accuracy.csv > /dev/null
tail -n +2 bench/results/plan_accuracy.csv
