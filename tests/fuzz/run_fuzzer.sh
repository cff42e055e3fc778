#!/usr/bin/env bash
# Builds a libFuzzer target with clang (ASan + UBSan) and runs it for a bounded time on a
# copy of its committed seed corpus. Used by ctest (fuzz.*); exit 77 = skipped (no clang or
# no libFuzzer runtime). Usage: run_fuzzer.sh NAME SECONDS BUILD_DIR
set -euo pipefail
name=$1 seconds=$2 build=$3
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)
command -v clang++ > /dev/null || { echo "fuzz.$name: clang++ not found, skipped"; exit 77; }
mkdir -p "$build"
exe="$build/${name}_fuzzer"
scene_sources=("$root/scene/scene_loader.cpp" "$root/scene/json_scene.cpp" "$root/scene/obj_scene.cpp"
               "$root/scene/obj_reader.cpp" "$root/scene/cornell_box.cpp" "$root/scene/cornell_materials.cpp"
               "$root/scene/ply_mesh.cpp" "$root/scene/scene_framing.cpp" "$root/scene/input_file.cpp"
               "$root/scene/line_reader.cpp" "$root/scene/progress_stream.cpp"
               "$root/scene/gltf_scene.cpp" "$root/scene/texture_image.cpp" "$root/scene/exr_encoder.cpp"
               "$root/scene/exr_header_check.cpp")
defines=()
case $name in
  obj_mesh) sources=("$here/obj_mesh_fuzzer.cpp" "$root/scene/obj_mesh.cpp" "$root/scene/obj_reader.cpp"
                    "$root/scene/input_file.cpp" "$root/scene/line_reader.cpp" "$root/scene/progress_stream.cpp")
            corpus_name=obj ;;
  scene_obj) sources=("$here/scene_fuzzer.cpp" "${scene_sources[@]}"); defines=(-DLUCENT_FUZZ_EXTENSION='".obj"')
             corpus_name=obj ;;
  scene_json) sources=("$here/scene_fuzzer.cpp" "${scene_sources[@]}"); defines=(-DLUCENT_FUZZ_EXTENSION='".json"')
              corpus_name=json ;;
  scene_ply) sources=("$here/scene_fuzzer.cpp" "${scene_sources[@]}"); defines=(-DLUCENT_FUZZ_EXTENSION='".ply"')
             corpus_name=ply ;;
  scene_gltf) sources=("$here/scene_fuzzer.cpp" "${scene_sources[@]}"); defines=(-DLUCENT_FUZZ_EXTENSION='".gltf"')
              corpus_name=gltf ;;  # .gltf: the loader tells GLB containers by their magic
  *) echo "unknown fuzz target $name" >&2; exit 2 ;;
esac
libs=(-ltinyobjloader -ltinygltf -lstb)  # tinygltf: Debian's shared build (not instrumented)
if ! clang++ -std=c++20 -O1 -g -fsanitize=fuzzer,address,undefined -fno-sanitize-recover=undefined \
     "${defines[@]}" -I "$root/include" -I "$root" -I /usr/include/stb "${sources[@]}" "${libs[@]}" -o "$exe" 2> "$build/${name}_build.log"; then
    if grep -q "libclang_rt.fuzzer\|fsanitize=fuzzer" "$build/${name}_build.log"; then
        echo "fuzz.$name: no libFuzzer runtime (libclang-rt-14-dev), skipped"; exit 77
    fi
    cat "$build/${name}_build.log" >&2
    exit 1
fi
corpus="$build/${name}_corpus"
rm -rf "$corpus" && mkdir -p "$corpus" && cp "$here/corpus/$corpus_name"/* "$corpus/"
cd "$build"
"$exe" -max_total_time="$seconds" -error_exitcode=1 -timeout=5 -rss_limit_mb=2048 -print_final_stats=1 "$corpus" 2>&1 | tail -20
