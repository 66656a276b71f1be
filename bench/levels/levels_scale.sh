#!/usr/bin/env bash
# The level size ladder: generated towns from 4x4 to 32x32 blocks, the lamp series on the 16x16 town and a 3x3
# tiling of Sponza, each baked under /usr/bin/time -v. Appends one row per run to bench/results/levels_scale.csv
# (wall and CPU seconds, peak memory, atlas texels, every stage's seconds, the 1-minute load average at start
# and end). From the repository root after a Release build:
#   bash bench/levels/levels_scale.sh [IRBAKE] [RUNS]
#   LADDER="town4 town8" bash bench/levels/levels_scale.sh      # a subset, by name
# Names: town4 town8 town16 town32 (sun + sky + lamps, two per block; town32 2,000 lamps at --quality preview),
# lamps_sunsky lamps_range lamps_norange (16x16 town with 1,000 lamp posts, --quality preview, the texel density
# of lamps_sunsky: no lights / 1,000 lamps with range / without), sponza3x3 (default quality, sun + sky),
# town32_shards sponza3x3_shards (the same bakes as 2 shards + irbake merge, run one after the other).
# Scenes are written into build/levels; Sponza is read from ../shared/scenes (skipped when absent).
set -euo pipefail
IRBAKE=$(readlink -f "${1:-build/baker/irbake}")
RUNS=${2:-3}
LADDER=${LADDER:-"town4 town8 town16 lamps_sunsky lamps_range lamps_norange sponza3x3 town32 town32_shards sponza3x3_shards"}
CSV=bench/results/levels_scale.csv
W=build/levels
SPONZA=../shared/scenes/dabrovic_sponza/sponza.glb
SUN_SKY=(--sun 0.35,-1,0.2,5 --sky 0.4,0.5,0.7)
COMMIT=${COMMIT:-$(git log -1 --format=%h -- baker shaders CMakeLists.txt)}
mkdir -p $W

scene() {  # name -> path of its glb (generated on first use)
  local town=bench/levels/town.py
  case $1 in
    town4) [[ -f $W/town4.glb ]] || python3 $town $W/town4.glb --blocks 4 --lamps 32 >&2; echo $W/town4.glb ;;
    town8) [[ -f $W/town8.glb ]] || python3 $town $W/town8.glb --blocks 8 --lamps 128 >&2; echo $W/town8.glb ;;
    town16) [[ -f $W/town16.glb ]] || python3 $town $W/town16.glb --blocks 16 --lamps 512 >&2; echo $W/town16.glb ;;
    town32) [[ -f $W/town32.glb ]] || python3 $town $W/town32.glb --blocks 32 --lamps 2000 --cell 2.2 >&2
            echo $W/town32.glb ;;
    posts) [[ -f $W/town16_posts.glb ]] || python3 $town $W/town16_posts.glb --blocks 16 --lamps 1000 --no-lights >&2
           echo $W/town16_posts.glb ;;
    range) [[ -f $W/town16_lamps.glb ]] || python3 $town $W/town16_lamps.glb --blocks 16 --lamps 1000 >&2
           echo $W/town16_lamps.glb ;;
    norange) [[ -f $W/town16_lamps_norange.glb ]] ||
               python3 $town $W/town16_lamps_norange.glb --blocks 16 --lamps 1000 --range 0 >&2
             echo $W/town16_lamps_norange.glb ;;
    sponza3x3) [[ -f $W/sponza3x3.glb ]] || python3 bench/levels/sponza_tiles.py $SPONZA $W/sponza3x3.glb --n 3 >&2
               echo $W/sponza3x3.glb ;;
  esac
}

now() { date +%s.%N; }
since() { python3 -c "import sys, time; print(round(time.time() - float(sys.argv[1]), 1))" "$1"; }
load1() { cut -d' ' -f1 /proc/loadavg; }

bake() {  # name blocks scene options...: RUNS one-machine bakes
  local name=$1 blocks=$2 file=$3; shift 3
  for r in $(seq 1 "$RUNS"); do
    local out=$W/out_$name load=$(load1) t0=$(now)
    /usr/bin/time -v -o $W/time_$name.txt "$IRBAKE" bake "$file" -o "$out" "$@" > $W/log_$name.txt 2>&1 ||
      { echo "levels_scale: $name failed (see $W/log_$name.txt)"; tail -3 $W/log_$name.txt; return 1; }
    local wall=$(since "$t0")
    python3 bench/levels/scale_row.py $CSV --report "$out/report.json" --time $W/time_$name.txt \
      --log $W/log_$name.txt --scene "$name" --blocks "$blocks" --options "$*" --run "$r" --wall "$wall" \
      --commit "$COMMIT" --load-start "$load"
  done
}

shards() {  # name blocks scene options...: one bake as 2 shards and a merge, one after the other
  local name=$1 blocks=$2 file=$3; shift 3
  local load=$(load1) t0=$(now) times=() logs=() dirs=()
  for k in 1 2; do
    /usr/bin/time -v -o $W/time_${name}_$k.txt "$IRBAKE" bake "$file" -o $W/out_${name}_$k --shard $k/2 "$@" \
      > $W/log_${name}_$k.txt 2>&1 || { echo "levels_scale: $name shard $k failed"; tail -3 $W/log_${name}_$k.txt; return 1; }
    times+=(--time $W/time_${name}_$k.txt); dirs+=($W/out_${name}_$k)
  done
  /usr/bin/time -v -o $W/time_${name}_merge.txt "$IRBAKE" merge "${dirs[@]}" -o $W/out_$name \
    > $W/log_${name}_merge.txt 2>&1 || { echo "levels_scale: $name merge failed"; tail -3 $W/log_${name}_merge.txt; return 1; }
  local wall=$(since "$t0")
  python3 bench/levels/scale_row.py $CSV --report $W/out_$name/report.json "${times[@]}" \
    --time $W/time_${name}_merge.txt --log $W/log_${name}_merge.txt --scene "$name" --blocks "$blocks" \
    --options "--shard 1/2 + 2/2 + merge $*" --run 1 --wall "$wall" --commit "$COMMIT" --load-start "$load"
}

lamp_tpu() {  # the texel density of the lamp series: lamps_sunsky's, or the auto density of its scene
  if [[ -f $W/out_lamps_sunsky/report.json ]]; then
    python3 -c "import json; print(repr(json.load(open('$W/out_lamps_sunsky/report.json'))['atlas']['texelsPerUnit']))"
  fi
}

for name in $LADDER; do
  case $name in
    town4) bake town4 4 "$(scene town4)" "${SUN_SKY[@]}" ;;
    town8) bake town8 8 "$(scene town8)" "${SUN_SKY[@]}" ;;
    town16) bake town16 16 "$(scene town16)" "${SUN_SKY[@]}" ;;
    town32) bake town32 32 "$(scene town32)" "${SUN_SKY[@]}" --quality preview ;;
    town32_shards) shards town32_shards 32 "$(scene town32)" "${SUN_SKY[@]}" --quality preview ;;
    lamps_sunsky) bake lamps_sunsky 16 "$(scene posts)" "${SUN_SKY[@]}" --quality preview ;;
    lamps_range|lamps_norange)
      tpu=$(lamp_tpu); [[ -n $tpu ]] || { echo "levels_scale: run lamps_sunsky first (its texel density)"; exit 2; }
      file=$(scene ${name#lamps_})
      bake $name 16 "$file" "${SUN_SKY[@]}" --quality preview --texels-per-unit "$tpu" ;;
    sponza3x3|sponza3x3_shards)
      [[ -f $SPONZA ]] || { echo "levels_scale: $SPONZA not found, $name skipped"; continue; }
      if [[ $name == sponza3x3 ]]; then bake sponza3x3 0 "$(scene sponza3x3)" "${SUN_SKY[@]}"
      else shards sponza3x3_shards 0 "$(scene sponza3x3)" "${SUN_SKY[@]}"; fi ;;
    *) echo "levels_scale: unknown ladder name $name"; exit 2 ;;
  esac
done
