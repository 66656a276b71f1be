#!/usr/bin/env bash
# Installs the npm packages of runtime/web (three, puppeteer-core, gltf-validator, gltfpack, @babylonjs/core and
# @babylonjs/loaders, the glTF-Transform CLI and libraries; versions pinned in runtime/web/package.json) into
# BUILD_DIR/web/node_modules, where the web tests look for them.
# Idempotent: does nothing when the installed versions already match. Needs Debian nodejs + npm
# (scripts/install-deps.sh). Usage: scripts/install-web-deps.sh [BUILD_DIR]   (default: build)
set -euo pipefail
cd "$(dirname "$0")/.."
build="${1:-build}"
dest="$build/web"
mkdir -p "$dest"
if ! command -v npm >/dev/null 2>&1; then
  echo "install-web-deps: npm not found (scripts/install-deps.sh installs it); the web tests will be skipped" >&2
  exit 0
fi
installed() {
  for m in three puppeteer-core gltf-validator gltfpack @babylonjs/core @babylonjs/loaders @gltf-transform/core \
           @gltf-transform/extensions @gltf-transform/functions; do
    [[ -d "$dest/node_modules/$m" ]] || return 1
  done
  [[ -x "$dest/node_modules/.bin/gltf-transform" ]]
}
if [[ -f "$dest/package.json" ]] && cmp -s runtime/web/package.json "$dest/package.json" && installed; then
  echo "install-web-deps: node modules present in $dest, nothing to install"
  exit 0
fi
cp runtime/web/package.json "$dest/package.json"
echo "install-web-deps: npm install into $dest"
# puppeteer-core never downloads a browser: the tests use Debian's /usr/bin/chromium.
(cd "$dest" && npm install --no-audit --no-fund --loglevel=error)
echo "install-web-deps: done"
