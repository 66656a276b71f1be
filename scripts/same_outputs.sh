#!/usr/bin/env bash
# same_outputs.sh IRBAKE OUTDIR [BASELINE_DIR]: the check a refactoring passes. Bakes four option sets
# (Cornell default; Sponza --sun --sky; the helmet --directional; Cornell on Embree, --directional, final gather
# on) into OUTDIR/{cornell,sponza,helmet,embree} and, with BASELINE_DIR (the same run of the previous build),
# compares every written file except report.json, the logs and the manifest with cmp. Exit 0 when all match.
set -uo pipefail
irbake=$(readlink -f "$1"); out=$2; base=${3:-}
shared=$(cd "$(dirname "$0")/../.." && pwd)/shared/scenes   # ../shared beside the repository
mkdir -p "$out"; rm -rf "$out"/{cornell,sponza,helmet,embree,samples}
"$irbake" samples "$out/samples" >/dev/null || { echo "samples failed"; exit 1; }
cornell=$(ls "$out"/samples/cornell*.gltf | head -1)
run() { local name=$1; shift; "$irbake" bake "$@" -o "$out/$name" --quiet > "$out/$name.log" 2>&1 || { echo "FAIL bake $name (see $out/$name.log)"; }; }
run cornell "$cornell"
run sponza "$shared/dabrovic_sponza/sponza.glb" --sun 0.35,-1,0.2,5 --sky 0.4,0.5,0.7
run helmet "$shared/damaged_helmet/DamagedHelmet.gltf" --directional
run embree "$cornell" --backend embree --directional --final-gather on
[[ -z "$base" ]] && exit 0
bad=0
for set in cornell sponza helmet embree; do
  for f in $(cd "$base/$set" && find . -type f ! -name 'report.json' ! -name '*.log' ! -name '.irbake-manifest' | sort); do
    if ! cmp -s "$base/$set/$f" "$out/$set/$f"; then echo "DIFFERS $set/$f"; bad=1; fi
  done
  n1=$(cd "$base/$set" && find . -type f | wc -l); n2=$(cd "$out/$set" && find . -type f | wc -l)
  [[ $n1 == $n2 ]] || { echo "FILE COUNT $set: $n1 vs $n2"; bad=1; }
done
[[ $bad == 0 ]] && echo "SAME: all four option sets byte-identical" || echo "NOT SAME"
exit $bad
