#!/usr/bin/env bash
# Packs what a GPU machine needs to bake (bench/gpu/README.md): irbake and the GL test binaries from a
# Release build, the libraries they link (a GPU machine need not have them), the minimal image plugin (no
# OpenImageIO there) and the third-party scenes from ../shared. Writes .gpu/bundle.tar.xz (ignored).
#   bash bench/gpu/make_bundle.sh [BUILD]
set -euo pipefail
BUILD=${1:-build}
SHARED=../shared/scenes
[[ -d $SHARED ]] || { echo "make_bundle: $SHARED not found"; exit 1; }
S=$(mktemp -d)
trap 'rm -rf "$S"' EXIT
mkdir -p $S/g/bin $S/g/lib $S/g/shared/scenes/{cornell_box,dabrovic_sponza,sibenik} $S/g/src
cp $BUILD/baker/irbake $BUILD/baker/gl_test $BUILD/baker/glcontext_test $S/g/bin/
# Everything the binaries link but the C/C++ runtime (the image's own is newer than Debian 12's).
ldd $BUILD/baker/irbake $BUILD/baker/gl_test | awk '/=> \//{print $3}' | sort -u |
  grep -v -E '/lib(c|m|dl|pthread|rt|gcc_s|stdc\+\+)\.so' | xargs -I{} cp -L {} $S/g/lib/
g++ -std=c++17 -O2 -shared -fPIC -Ibaker bench/gpu/minimal_imageio_plugin.cpp -l:libstb.so.0 \
  -o $S/g/lib/libirbake_imageio_min.so
cp $SHARED/cornell_box/cornell_box.glb $S/g/shared/scenes/cornell_box/
cp -r $SHARED/dabrovic_sponza/sponza.glb $SHARED/dabrovic_sponza/textures $S/g/shared/scenes/dabrovic_sponza/
python3 bench/levels/add_point_light.py $SHARED/sibenik/sibenik.glb $S/g/shared/scenes/sibenik/sibenik_lamp.glb 0,-8,0 2000
cp -r $SHARED/sibenik/textures $S/g/shared/scenes/sibenik/
cp -r $SHARED/damaged_helmet $SHARED/stanford_bunny $S/g/shared/scenes/
# The McGuire box with its light, as the Cycles bench writes it (bench/cycles/scenes.py).
mkdir -p $S/g/shared/scenes/mcguire
python3 bench/cycles/scenes.py mcguire $S/g/shared/scenes/mcguire > /dev/null
mkdir -p .gpu
tar -C $S -cJf .gpu/bundle.tar.xz g
ls -la .gpu/bundle.tar.xz
