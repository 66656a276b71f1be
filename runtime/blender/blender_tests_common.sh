# Sourced by the Blender client tests (usage: TEST.sh IRBAKE IRVIEW WORK_DIR): their arguments, a skip (exit 77)
# without Blender or the numpy its glTF importer needs, and an empty WORK_DIR.
irbake="$1" irview="$2" work="$3"
skip() { echo "SKIPPED: $*"; exit 77; }
command -v blender >/dev/null 2>&1 || skip "blender not found (scripts/install-deps.sh installs Debian blender)"
blender --background --factory-startup --python-expr "import numpy" >/dev/null 2>&1 \
  || skip "Blender's Python cannot import numpy, which its glTF importer needs (Debian python3-numpy)"
rm -rf "$work" && mkdir -p "$work"
