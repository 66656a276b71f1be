#!/usr/bin/env bash
# Builds and runs the glTF loader's libFuzzer harness (tests/fuzz/README.md).
# Usage: run_fuzz.sh SOURCE_DIR WORK_DIR IRBAKE_EXE SECONDS [libFuzzer options...]
#   WORK_DIR (in the build folder) receives the clang build, the seed corpus, the growing corpus,
#   crash reproducers and fuzz.log. Exit 0: no finding; 1: a finding (reproducer path printed);
#   77: skipped (no clang++ or no libFuzzer runtime), as ctest's SKIP_RETURN_CODE.
set -euo pipefail
src=$(cd "$1" && pwd); work=$2; irbake=$3; seconds=$4; shift 4
mkdir -p "$work"; work=$(cd "$work" && pwd)

cxx=${IRBAKE_FUZZ_CXX:-$(command -v clang++ || command -v clang++-14 || true)}
if [[ -z "$cxx" ]]; then
  echo "SKIP: clang++ not found (scripts/install-deps.sh installs clang and libclang-rt-14-dev)"; exit 77
fi
if ! echo 'extern "C" int LLVMFuzzerTestOneInput(const unsigned char*, unsigned long) { return 0; }' |
     "$cxx" -x c++ -fsanitize=fuzzer - -o "$work/probe" >/dev/null 2>&1; then
  echo "SKIP: $cxx cannot link libFuzzer (the libclang-rt-14-dev package is missing)"; exit 77
fi
rm -f "$work/probe"

# The harness build: a separate clang project (its own cache, so the gcc build is untouched).
launcher=()
command -v ccache >/dev/null && launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
cmake -S "$src/tests/fuzz" -B "$work/build" -DCMAKE_CXX_COMPILER="$cxx" -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  "${launcher[@]}" >"$work/configure.log" || { cat "$work/configure.log"; exit 1; }
cmake --build "$work/build" -j2 >"$work/build.log" || { tail -50 "$work/build.log"; exit 1; }

# Seeds: our sample scenes, each as a self-contained GLB and .gltf.
rm -rf "$work/samples" "$work/seeds"
"$irbake" samples "$work/samples" --quiet
"$work/build/make_seed_corpus" "$work/samples" "$work/seeds"
mkdir -p "$work/corpus" "$work/findings"

cd "$work"
set +e
# One worker, 1 GB of RSS at most (a finding beyond that), 10 s per input at most.
"$work/build/gltf_loader_fuzz" "$work/corpus" "$work/seeds" -dict="$src/tests/fuzz/gltf.dict" \
  -max_total_time="$seconds" -rss_limit_mb=1024 -malloc_limit_mb=1024 -timeout=10 -max_len=65536 \
  -artifact_prefix="$work/findings/" -print_final_stats=1 "$@" 2>"$work/fuzz.log"
status=$?
set -e
grep -E '^#[0-9]+ +(INITED|DONE)|stat::number_of_executed_units|stat::average_exec_per_sec|stat::peak_rss_mb' "$work/fuzz.log" || true
if [[ $status -ne 0 ]]; then
  tail -60 "$work/fuzz.log"
  echo "FINDING: reproducer(s) in $work/findings:"; ls -l "$work/findings"
  exit 1
fi
echo "no findings in ${seconds} s ($(ls "$work/corpus" | wc -l) corpus inputs)"
