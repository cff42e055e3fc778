#!/usr/bin/env bash
# Runs one libFuzzer target, built by build_fuzzers.sh (ctest's fixture fuzz.build), for a
# fixed time on a copy of its committed seed corpus. Every seed runs first, so every input
# that ever crashed a loader (the corpus keeps them) is a regression test; any crash, leak,
# UBSan report or 5 s hang fails the test. Used by ctest (fuzz.*); exit 77 = skipped (the
# build was: no clang or no libFuzzer runtime). Usage: run_fuzzer.sh NAME SECONDS BUILD_DIR
set -euo pipefail
name=$1 seconds=$2 build=$3
here=$(cd "$(dirname "$0")" && pwd)
if [ -f "$build/skipped" ]; then cat "$build/skipped"; exit 77; fi
case $name in
  obj_mesh) exe=obj_mesh_fuzzer corpus_name=obj ;;
  scene_obj) exe=scene_fuzzer corpus_name=obj extension=.obj ;;
  scene_json) exe=scene_fuzzer corpus_name=json extension=.json ;;
  scene_ply) exe=scene_fuzzer corpus_name=ply extension=.ply ;;
  scene_gltf) exe=scene_fuzzer corpus_name=gltf extension=.gltf ;;  # GLB is told by its magic
  *) echo "unknown fuzz target $name" >&2; exit 2 ;;
esac
[ -x "$build/$exe" ] || { echo "fuzz.$name: $build/$exe is missing; fuzz.build failed or was skipped" >&2; exit 1; }
export LUCENT_FUZZ_EXTENSION=${extension:-.obj}
corpus="$build/${name}_corpus"
rm -rf "$corpus" && mkdir -p "$corpus" && cp "$here/corpus/$corpus_name"/* "$corpus/"
cd "$build"
"./$exe" -max_total_time="$seconds" -error_exitcode=1 -timeout=5 -rss_limit_mb=2048 -print_final_stats=1 "$corpus" 2>&1 | tail -20
