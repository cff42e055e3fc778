#!/usr/bin/env bash
# Builds a self-contained bundle in .gpu-bundle/ for a GPU machine that has the NVIDIA
# driver but not Debian's packages: the binaries, the Debian runtime libraries they load
# (run through the bundled loader, so the machine's own glibc does not matter) and the
# benchmark scenes. On that machine: `.gpu-bundle/run .gpu-bundle/bin/lucent ...`.
# Embree is left out (the GPU benchmark compares against Lucent's CPU backend), and so is the
# viewer (the GPU machine has no display). `lucent bench present` is in: it needs only glvnd's
# OpenGL and EGL, whose NVIDIA vendor library the GPU machine has.
set -euo pipefail
cd "$(dirname "$0")/.."
out=.gpu-bundle
# LUCENT_BUNDLE_BUILD=build bundles an existing build tree instead (quicker; its instruction
# set must suit the GPU machine's processor).
build=${LUCENT_BUNDLE_BUILD:-build-gpu-bundle}
if [ -z "${LUCENT_BUNDLE_BUILD:-}" ]; then
  cmake -S . -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release -DLUCENT_NATIVE=OFF \
        -DCMAKE_CXX_FLAGS="-mavx2 -mfma -mf16c -mbmi -mbmi2 -mlzcnt -mpopcnt" \
        -DCMAKE_DISABLE_FIND_PACKAGE_embree=ON -DCMAKE_DISABLE_FIND_PACKAGE_glfw3=ON > /dev/null
fi
# Only the suites scripts/gpu-check.sh runs on the GPU (the carry is 64 MiB).
# LUCENT_BUNDLE_SUITES="igi whitted" bundles those alone, LUCENT_BUNDLE_SUITES= none, and
# LUCENT_BUNDLE_EXAMPLES=0 leaves the examples out: a quicker bundle for one measurement.
suites=${LUCENT_BUNDLE_SUITES-"programs device_api nodes variables exceptions validation occlusion ray_control motion denoise svgf spheres curves textures igi_dielectric scale soak gltf whitted backend igi radiosity direct emitters_textures
        fog pathtracer hair multi_device gpu_bvh_builder display modules"}
targets="lucent_cli lucent_embed_module"
python=0  # the Python module: its objects travel, and gpu-check.sh's `python` step links it there
if grep -q '^LUCENT_PYTHON:BOOL=ON' "$build/CMakeCache.txt"; then python=1; targets="$targets lucent_python"; fi
for t in $suites; do targets="$targets ${t}_test"; done
cmake --build "$build" -j"$(nproc)" --target $targets
rm -rf "$out"
mkdir -p "$out/bin" "$out/lib"
for t in $suites; do cp "$build/tests/${t}_test" "$out/bin/"; done
cp "$build/lucent" "$out/bin/"
# The examples, built as a user builds them: against the installed package.
prefix="$PWD/$build/prefix"
[ "${LUCENT_BUNDLE_EXAMPLES:-1}" = 0 ] || cmake --install "$build" --prefix "$prefix" > /dev/null
for dir in examples/*/; do
  [ "${LUCENT_BUNDLE_EXAMPLES:-1}" = 0 ] && break
  [ -f "$dir/CMakeLists.txt" ] || continue  # examples/python: scripts, run by gpu-check.sh python
  name=$(basename "$dir")
  cmake -S "$dir" -B "$build/examples/$name" -G Ninja -DCMAKE_BUILD_TYPE=Release \
        -DCMAKE_PREFIX_PATH="$prefix" -DCMAKE_CXX_FLAGS="-mavx2 -mfma" > /dev/null
  cmake --build "$build/examples/$name" -j"$(nproc)"
  cp "$build/examples/$name/$name" "$out/bin/example-$name"
done
strip --strip-unneeded "$out"/bin/*  # symbols are not needed there, and the carry is 64 MiB
if [ "$python" = 1 ]; then
  # The GPU machine's Python is another version than the one built for here, so the
  # extension is linked there (gpu-check.sh python) from the bindings' sources in the tree,
  # these static libraries and objects, and the Debian libraries they load (not the C and
  # C++ runtimes: that machine's own, newer ones serve).
  mkdir -p "$out/python/lib" "$out/python/objects" "$out/python/so"
  cp "$build"/liblucent.a "$build"/liblucent_scene.a "$build"/liblucent_bench.a "$out/python/lib/"
  # The samples are an object library (their registrars must be linked, not pulled from an
  # archive): the objects CMake lists for it travel, samples/igi/igi.cpp.o as
  # samples_igi_igi.cpp.o.
  while read -r o; do
    name=${o#*/lucent_samples.dir/}; name=${name#./}
    cp "$o" "$out/python/objects/$(echo "$name" | tr / _)"
  done < "$build/lucent_samples_objects.txt"
  cp "$build"/CMakeFiles/lucent_sample_programs.dir/lucent_modules/*/*.o \
     "$build"/CMakeFiles/lucent_bench_programs.dir/lucent_modules/*/*.o \
     "$build"/python/CMakeFiles/lucent_python.dir/lucent_modules/*/*.o "$out/python/objects/"
  for lib in $(ldd "$build"/python/lucent/_lucent*.so | awk '/=>/ {print $3}' |
               grep -vE '/(libc|libm|libstdc\+\+|libgcc_s|libpthread|libdl|librt)\.so'); do
    cp -L "$lib" "$out/python/so/"
  done
fi
for lib in $(ldd "$out"/bin/* | awk '/=>/ {print $3}' | sort -u); do cp -L "$lib" "$out/lib/"; done
cp -L /lib64/ld-linux-x86-64.so.2 "$out/lib/"
scenes=../shared/scenes
if [ -d "$scenes" ]; then
  tar czf "$out/scenes.tgz" -C "$scenes" sponza.obj sibenik.obj bunny.obj dragon.obj cornell cameras.txt
fi
cat > "$out/run" <<'RUN'
#!/bin/sh
# Runs a bundled program with the bundled loader and libraries.
here=$(cd "$(dirname "$0")" && pwd)
exec "$here/lib/ld-linux-x86-64.so.2" --library-path "$here/lib" "$@"
RUN
chmod +x "$out/run"
du -sh "$out"
