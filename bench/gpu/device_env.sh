# Sourced by device_run.sh and device_scenes.sh on the GPU machine: the bundle's paths and bake().
# R (the results folder) is set by the caller before sourcing.
G=/tmp/g
mkdir -p "$R"
export LD_LIBRARY_PATH=$G/lib IRBAKE_IMAGEIO_PLUGIN=$G/lib/libirbake_imageio_min.so IRBAKE_SOURCE_DIR=$G/src
export __EGL_VENDOR_LIBRARY_FILENAMES=/usr/local/nvidia/share/glvnd/egl_vendor.d/10_nvidia.json
B=$G/bin/irbake
S=$G/shared/scenes
bake() {  # tag timeout command...: the command's -o is $R/tag; its wall time and last lines printed
  local tag=$1 lim=$2; shift 2
  local t0=$(date +%s.%N)
  timeout $lim "$@" -o $R/$tag --quiet > $R/$tag.log 2>&1
  local rc=$?
  echo "$tag rc=$rc wall=$(awk -v a=$t0 -v b=$(date +%s.%N) 'BEGIN{printf "%.2f", b-a}') $(grep -o '"backend": *"[a-z]*"' $R/$tag/report.json 2>/dev/null)"
  grep -v -E "^/tmp/g/results" $R/$tag.log | tail -2
}
