#!/usr/bin/env bash
# The portable GLB on Sponza (../shared/scenes; skipped with a message when absent) baked with
# --sun 0.35,-1,0.2,5 --sky 0.4,0.5,0.7 --portable: the file's size, its textures (count, largest side), the
# range, the clipped shares (all covered texels; without the emitters' texels), the portable step's seconds
# (report timings.seconds.portable), the report's peak memory and the process's (/usr/bin/time)
# → bench/results/portable_export.csv, one row per irbake given (this build's, another's to compare), labelled
# by LABEL where given, else by its version line.
# Usage: bench/portable_export.sh [LABEL=]IRBAKE... (e.g. build/baker/irbake)
set -euo pipefail
src=$(cd "$(dirname "$0")/.." && pwd)
[[ $# -ge 1 ]] || { echo "usage: bench/portable_export.sh [LABEL=]IRBAKE..." >&2; exit 2; }
sponza="$src/../shared/scenes/dabrovic_sponza/sponza.glb"
if [[ ! -f "$sponza" ]]; then echo "skipped: $sponza absent"; exit 0; fi
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
mkdir -p "$work" "$src/bench/results"
csv="$src/bench/results/portable_export.csv"
[[ -f "$csv" ]] || echo "date,irbake,scene,size_mb,textures,largest_side,range,clip_percent,lit_clip_percent,portable_s,report_peak_mib,process_peak_mib" > "$csv"
light=(--sun 0.35,-1,0.2,5 --sky 0.4,0.5,0.7)

measure() {  # [LABEL=]IRBAKE
  local irbake out label
  irbake=$(realpath "${1#*=}")
  label="${1%%=*}"
  [[ "$1" == *=* ]] || label="$("$irbake" --version | head -1)"
  out="$work/$(basename "$(mktemp -u)")"
  /usr/bin/time -f "%M" -o "$out.mem" "$irbake" bake "$sponza" -o "$out" "${light[@]}" --quiet \
    --portable="$out/portable.glb" >/dev/null
  python3 - "$csv" "$label" "$out" "$(cat "$out.mem")" <<'PY'
import datetime, json, os, struct, sys
csv, version, out, kb = sys.argv[1:]
r = json.load(open(os.path.join(out, "report.json")))
p = r["portable"]
glb = open(p["file"], "rb").read()
n = struct.unpack_from("<I", glb, 12)[0]
doc = json.loads(glb[20:20 + n])
pages = p["pages"]
covered_share = lambda key: 100.0 * max(pg.get(key, pg["clippedFraction"]) for pg in pages)
sides = [max(t["width"], t["height"]) for pg in pages for t in pg.get("tiles", [pg])]
with open(csv, "a") as f:
    f.write(f"{datetime.datetime.utcnow():%Y-%m-%dT%H:%MZ},{version.replace(',', ' ')},sponza_sun_sky,"
            f"{len(glb) / 1e6:.1f},{len(doc.get('images', []))},{max(sides)},{p.get('range', 1.0):.3f},"
            f"{covered_share('clippedFraction'):.3f},{covered_share('litClippedFraction'):.3f},"
            f"{r['timings']['seconds'].get('portable', float('nan')):.1f},{r['timings']['memoryPeakMiB']:.0f},"
            f"{int(kb) / 1024:.0f}\n")
PY
  tail -1 "$csv"
  rm -rf "$out"
}

for irbake in "$@"; do measure "$irbake"; done
