#!/usr/bin/env bash
# README command (b): install what is missing, build, run every test.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
bash scripts/build.sh
bash scripts/install-web-deps.sh build
cd build
ctest --output-on-failure -j"$(nproc)" --timeout 600
