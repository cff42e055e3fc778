#!/usr/bin/env bash
# Builds the two libFuzzer executables with clang (ASan + UBSan) into BUILD_DIR, once for all
# the fuzz.* tests (ctest's fixture fuzz.build): obj_mesh_fuzzer, and scene_fuzzer, whose
# loader the run picks with LUCENT_FUZZ_EXTENSION. Each source is compiled once, in parallel
# (the five targets used to compile the same fifteen loaders each: 7 minutes of a 2-core CI
# machine's CPU). Exit 77 = skipped (no clang, or no libFuzzer runtime: libclang-rt-14-dev).
# Usage: build_fuzzers.sh BUILD_DIR
set -euo pipefail
build=$1
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)
skip() {  # REASON: run_fuzzer.sh skips the targets too, with the reason
  echo "fuzz.build: $1, skipped" | tee "$build/skipped"; exit 77
}
mkdir -p "$build"
rm -f "$build/skipped" "$build/obj_mesh_fuzzer" "$build/scene_fuzzer"
command -v clang++ > /dev/null || skip "clang++ not found"
loaders=(scene_loader json_scene obj_scene obj_reader obj_mesh cornell_box cornell_materials ply_mesh
         scene_framing input_file line_reader progress_stream gltf_scene texture_image exr_encoder
         exr_header_check)
objects="$build/objects"
mkdir -p "$objects"
log="$build/build.log"
: > "$log"
flags=(-std=c++20 -O1 -g -fno-sanitize-recover=undefined -I "$root/include" -I "$root" -I /usr/include/stb)
compile() {  # SOURCE OBJECT
  clang++ "${flags[@]}" -fsanitize=fuzzer-no-link,address,undefined -c "$1" -o "$2"
}
sources=()
for loader in "${loaders[@]}"; do sources+=("$root/scene/$loader.cpp"); done
sources+=("$here/obj_mesh_fuzzer.cpp" "$here/scene_fuzzer.cpp")
jobs=$(nproc)
pids=() failed=0
for source in "${sources[@]}"; do
  object="$objects/$(basename "$source" .cpp).o"
  compile "$source" "$object" >> "$log" 2>&1 &
  pids+=($!)
  if [ ${#pids[@]} -ge "$jobs" ]; then wait "${pids[0]}" || failed=1; pids=("${pids[@]:1}"); fi
done
for pid in "${pids[@]}"; do wait "$pid" || failed=1; done
if [ $failed -ne 0 ]; then cat "$log" >&2; exit 1; fi
libs=(-ltinyobjloader -ltinygltf -lstb)  # tinygltf: Debian's shared build (not instrumented)
link() {  # NAME OBJECT...
  local name=$1; shift
  if ! clang++ -fsanitize=fuzzer,address,undefined "$@" "${libs[@]}" -o "$build/$name" >> "$log" 2>&1; then
    if grep -q "libclang_rt.fuzzer\|fsanitize=fuzzer" "$log"; then
      skip "no libFuzzer runtime (libclang-rt-14-dev)"
    fi
    cat "$log" >&2
    exit 1
  fi
}
objects_of() {  # NAME...: their object files
  local name; for name in "$@"; do printf '%s\n' "$objects/$name.o"; done
}
mapfile -t obj_mesh_objects < <(objects_of obj_mesh_fuzzer obj_mesh obj_reader input_file line_reader progress_stream)
scene_loaders=()  # obj_mesh.cpp is the OBJ mesh fuzzer's loader; the scenes read OBJ through obj_scene.cpp
for loader in "${loaders[@]}"; do [ "$loader" = obj_mesh ] || scene_loaders+=("$loader"); done
mapfile -t scene_objects < <(objects_of scene_fuzzer "${scene_loaders[@]}")
link obj_mesh_fuzzer "${obj_mesh_objects[@]}"
link scene_fuzzer "${scene_objects[@]}"
