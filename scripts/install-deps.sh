#!/usr/bin/env bash
# Installs the Debian packages irbake needs, and only those that are missing.
# Idempotent: when everything is present it installs nothing and says so.
# Usage: scripts/install-deps.sh [--bench]   (--bench adds the plotting tools for bench/)
set -euo pipefail

packages=(
  cmake g++ pkg-config
  libembree-dev            # Embree 3: ray tracing for the walk, the reference and the Embree backend
  libopenmesh-dev          # OpenMesh: half-edge meshes for the atlas
  libopenimageio-dev openimageio-tools   # OIIO: image decode and EXR output (its CMake config needs the tools)
  libglm-dev               # GLM: vector maths
  libtinygltf-dev          # tinygltf: glTF 2.0 parsing and writing
  libdraco-dev libmeshoptimizer-dev   # decoders of Draco- and meshopt-compressed glTF geometry
  libeigen3-dev            # Eigen: sparse solves for LSCM
  libtbb-dev               # TBB: parallel loops
  libepoxy-dev libegl-dev libgl1-mesa-dri libegl-mesa0   # GL entry points + headless EGL (Mesa llvmpipe)
  libglfw3-dev             # GLFW: the viewer's window
  libgtest-dev             # GoogleTest
  libbenchmark-dev         # Google Benchmark
  nlohmann-json3-dev       # JSON reports
  libcli11-dev             # CLI11: command-line options of irbake and irview
  libxxhash-dev            # xxHash: checksums of partials and checkpoints, hashes of scene files
  clang libclang-rt-14-dev # clang + libFuzzer runtime: the glTF loader's fuzz harness (tests/fuzz)
  xvfb xauth               # windowed viewer test without a display
  universal-ctags          # the long-function check (scripts/long_functions.py)
  chromium                 # runtime/web: the three.js viewer test in headless Chromium
  blender python3-numpy    # runtime/blender: the light-map add-on test (Blender 3.4's glTF importer needs numpy)
  slurm-wlm munge          # tests/slurm: a single-node Slurm on localhost bakes in shards (scripts/slurm)
)
# node + npm for runtime/web's tests (npm modules: scripts/install-web-deps.sh). Debian's nodejs and
# npm, unless a node with its own npm is already there (NodeSource's nodejs conflicts with Debian npm).
command -v node >/dev/null 2>&1 || packages+=(nodejs)
command -v npm >/dev/null 2>&1 || packages+=(npm)
if [[ "${1:-}" == "--bench" ]]; then
  packages+=(python3-matplotlib python3-openimageio)   # openimageio: bench/cycles reads EXRs
fi

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if [[ ${#missing[@]} -eq 0 ]]; then
  echo "install-deps: all ${#packages[@]} packages present, nothing to install"
  exit 0
fi

echo "install-deps: installing ${#missing[@]} missing package(s): ${missing[*]}"
SUDO=""
if [[ $(id -u) -ne 0 ]]; then
  if command -v sudo >/dev/null 2>&1; then SUDO="sudo"; else
    echo "install-deps: not root and no sudo; install these by hand: ${missing[*]}" >&2; exit 1
  fi
fi
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -q
$SUDO apt-get install -y -q --no-install-recommends "${missing[@]}"
echo "install-deps: done"
