#!/usr/bin/env bash
# layering.py refuses a pipeline file (other than the evaluator factory) that includes an evaluator's
# implementation: on a copy of baker/, the script and docs/architecture.md in WORK (inside the build folder),
# the clean copy passes, and with `#include "evaluators/gl/gl_backend.h"` planted in a pipeline source it
# exits 1 naming that file. Usage: layering_planted_include.sh SOURCE_ROOT WORK
set -u
src=$1 work=$2
rm -rf "$work" && mkdir -p "$work/scripts" "$work/docs" || exit 2
cp -r "$src/baker" "$work/" && cp "$src/scripts/layering.py" "$work/scripts/" &&
  cp "$src/docs/architecture.md" "$work/docs/" || exit 2

python3 "$work/scripts/layering.py" "$work" >"$work/clean.txt"
rc=$?
if [ $rc -ne 0 ]; then
  echo "FAIL: the clean copy was refused (exit $rc):"; cat "$work/clean.txt"; exit 1
fi

planted=baker/pipeline/bake_stages.cpp
echo '#include "evaluators/gl/gl_backend.h"' >>"$work/$planted"
python3 "$work/scripts/layering.py" "$work" >"$work/planted.txt"
rc=$?
cat "$work/planted.txt"
if [ $rc -ne 1 ]; then
  echo "FAIL: layering.py exited $rc on a planted GL include in $planted (expected 1)"; exit 1
fi
if ! grep -q "^$planted:[0-9]*: includes the gl evaluator's implementation" "$work/planted.txt"; then
  echo "FAIL: layering.py did not name $planted"; exit 1
fi
echo "PASS: the planted include in $planted is refused"
