# Shared by the web tests (sourced): checks for node, Chromium and the node modules, and skips (exit 77,
# ctest's SKIP_RETURN_CODE) with a message naming what is missing and how to get it.
skip() { echo "SKIPPED: $*"; exit 77; }
need_node_modules() {
  local modules="$1"; shift
  command -v node >/dev/null 2>&1 || skip "node not found (scripts/install-deps.sh installs Debian nodejs and npm)"
  for m in "$@"; do
    [[ -d "$modules/node_modules/$m" ]] || skip "$modules/node_modules/$m missing (run scripts/install-web-deps.sh BUILD_DIR)"
  done
}
# The start of a real-client test: three.js and puppeteer-core in MODULES, Debian's Chromium, and an empty
# WORK folder.
need_browser_client() {
  local modules="$1" work="$2"
  need_node_modules "$modules" three puppeteer-core
  [[ -x /usr/bin/chromium ]] || skip "/usr/bin/chromium not found (scripts/install-deps.sh installs Debian chromium)"
  rm -rf "$work" && mkdir -p "$work"
}
# The Cornell box sample baked into WORK/bake (more bake options after WORK) and irview's W×H (320×320)
# screenshot from its camera 0 in WORK/irview.png: what the client tests compare against. Sets w and h.
bake_cornell_and_irview() {
  local irbake="$1" irview="$2" work="$3"; shift 3
  "$irbake" samples "$work/samples" > "$work/samples.log"
  "$irbake" bake "$work/samples/cornell_box.gltf" -o "$work/bake" --vpls 512 --texels-per-unit 120 "$@" --quiet \
    > "$work/bake.log" 2>&1
  w=320 h=320
  "$irview" "$work/bake/scene.gltf" --camera 0 --width $w --height $h --screenshot "$work/irview.png" > "$work/irview.log" 2>&1
}
