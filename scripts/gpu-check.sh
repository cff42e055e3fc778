#!/usr/bin/env bash
# The CUDA checks and benchmarks, for a GPU machine (the `device` tool): run from the repo
# root after scripts/gpu-bundle.sh built .gpu-bundle/ on the development machine.
# Writes logs and images to $OUT (default gpu-out/). Usage: scripts/gpu-check.sh [STEP...]
# with steps: render examples samples tests igi pathtracer fog tea sanitizer sanitize bench builder present sweep
# profile hotspots multi python startup (several GPUs: MULTI_SUITES picks the suites run through --devices)
# (default: render tests sanitizer bench). LUCENT_GPU_CHECK_CACHE names a kernel cache folder
# to keep between runs (your own, e.g. under the tree's ignored build folders); by default
# each run compiles into a fresh private one.
set -uo pipefail
out=${OUT:-gpu-out}
mkdir -p "$out"
B=.gpu-bundle
R="$B/run"
steps=${*:-render tests sanitizer bench}
# The test binaries look for tests/ and the scenes where the build machine had them.
mkdir -p /work/shared/scenes
[ -e /work/main ] || ln -s "$PWD" /work/main
[ -f /work/shared/scenes/sponza.obj ] || tar xzf "$B/scenes.tgz" -C /work/shared/scenes
# A private scratch folder (mktemp: mode 0700, an unpredictable name) for the kernel cache
# and the logs, never a fixed path in /tmp that another user could plant first.
work=$(mktemp -d "${TMPDIR:-/tmp}/lucent-gpu-check.XXXXXX")
trap 'rm -rf "$work"' EXIT
export LUCENT_CACHE_DIR=${LUCENT_GPU_CHECK_CACHE:-$work/kernel-cache}
# Empties the kernel cache, so the next run compiles cold.
cold_cache() { rm -rf "$LUCENT_CACHE_DIR"; }
nvidia-smi -L

# compare A.png B.png LABEL: pixels differing by more than 10/255 (HIPRT's image test).
compare() {
    python3 - "$1" "$2" "$3" <<'PY'
import sys
import numpy as np
from PIL import Image
a = np.asarray(Image.open(sys.argv[1]).convert("RGB")).astype(int)
b = np.asarray(Image.open(sys.argv[2]).convert("RGB")).astype(int)
d = np.abs(a - b).max(axis=2)
print(f"CPU vs GPU {sys.argv[3]}: {(d > 10).sum()} of {d.size} pixels differ by more than 10/255 "
      f"({100.0 * (d > 10).sum() / d.size:.3f} %), max difference {d.max()}/255")
PY
}

for step in $steps; do
case $step in
render)
    cold_cache
    echo "== whitted 1024x1024: cold JIT, then cached, 1 spp, median of 500 launches"
    $R $B/bin/lucent render --sample whitted --backend cuda --size 1024x1024 --out "$out/whitted_cuda.png" --verbose
    $R $B/bin/lucent render --sample whitted --backend cuda --size 1024x1024 --out "$out/whitted_cuda.png" --verbose --repeat 500
    $R $B/bin/lucent render --sample whitted --backend cpu --size 1024x1024 --out "$out/whitted_cpu.png"
    compare "$out/whitted_cpu.png" "$out/whitted_cuda.png" whitted
    ;;
examples)
    # The examples built against the installed package: GPU against CPU, and the JIT of a
    # user's module cold, then from the disk cache.
    cold_cache
    # (programs-at-run-time is not run here: this machine's g++ builds modules for its own
    # C library, newer than the Debian one the bundle's programs run with. The Python step
    # runs modules compiled at run time on the GPU, through an extension linked here.)
    for e in first-program ambient-occlusion render-sample; do
        echo "== example $e: cuda (cold JIT), cuda (cached), cpu"
        $R $B/bin/example-$e --backend cuda --out "$out/${e}_cuda.png"
        $R $B/bin/example-$e --backend cuda --out "$out/${e}_cuda.png"
        $R $B/bin/example-$e --backend cpu --out "$out/${e}_cpu.png"
        compare "$out/${e}_cpu.png" "$out/${e}_cuda.png" "$e"
    done
    echo "== example ray-queries: cuda, cpu"
    $R $B/bin/example-ray-queries --backend cuda --out "$out/ray_queries_cuda.txt"
    $R $B/bin/example-ray-queries --backend cpu --out "$out/ray_queries_cpu.txt"
    # Visibility and triangle answers must be equal; distances within 1e-4 relative (the GPU's
    # fast-math division and FMAs round differently).
    python3 - "$out/ray_queries_cpu.txt" "$out/ray_queries_cuda.txt" <<'PY'
import sys
rows = [[l.split() for l in open(f) if not l.startswith("#")] for f in sys.argv[1:]]
cpu, gpu = rows
exact = sum(1 for a, b in zip(cpu, gpu) if len(a) == 2 and a != b)
tri = sum(1 for a, b in zip(cpu, gpu) if len(a) == 3 and a[2] != b[2])
far = sum(1 for a, b in zip(cpu, gpu) if len(a) == 3 and
          abs(float(a[1]) - float(b[1])) > 1e-4 * max(1.0, abs(float(a[1]))))
print(f"ray-queries CPU vs GPU: {len(cpu)} answers; {exact} visibility, {tri} triangle and "
      f"{far} distance answers differ (distance tolerance 1e-4 relative)")
PY
    echo "== modules_test on the GPU"
    LUCENT_TEST_BACKEND=cuda $R $B/bin/modules_test 2>&1 | tail -3
    ;;
tests)
    # Each test alone, so a crash is pinned on one test and the others still run.
    for t in programs device_api nodes variables exceptions validation occlusion ray_control motion denoise svgf gltf whitted backend igi radiosity direct emitters_textures fog pathtracer hair modules; do
        echo "== ${t}_test on the GPU"
        pass=0; fail=0
        for name in $($R $B/bin/${t}_test --gtest_list_tests | awk '/^[^ ]/ {s=$1} /^  / {print s $1}'); do
            if LUCENT_TEST_BACKEND=cuda $R $B/bin/${t}_test --gtest_filter="$name" > "$work/one.log" 2>&1; then
                pass=$((pass + 1))
            else
                fail=$((fail + 1)); echo "-- FAILED $name (exit $?)"; grep -vE "^\[|^Running|^Note:|invoke.cuh|__forceinline__|^ +\^$|note #" "$work/one.log" | head -12
            fi
        done
        echo "${t}_test on the GPU: $pass passed, $fail failed"
    done
    ;;
sweep)
    echo "== whitted 1024x1024 frame rate against kernel variants (NVRTC defines)"
    for v in "" "-maxrregcount=96" "-maxrregcount=128" "-DLUCENT_GPU_MIN_BLOCKS=3" \
             "--extra-device-vectorization" "-Xptxas=-dlcm=cg"; do
        echo "-- LUCENT_NVRTC_OPTIONS=$v"
        LUCENT_NVRTC_OPTIONS="$v" $R $B/bin/lucent render --sample whitted --backend cuda --size 1024x1024 --repeat 300 --out "$work/s.png" | grep -E "launch|JIT"
    done
    for c in 50; do
        echo "-- LUCENT_GPU_CARVEOUT=$c (shared memory share, default 0: L1 first)"
        LUCENT_GPU_CARVEOUT=$c $R $B/bin/lucent render --sample whitted --backend cuda --size 1024x1024 --repeat 300 --out "$work/s.png" | grep -E "launch"
    done
    ;;
samples)
    echo "== every sample on the CPU and the GPU: images compared"
    for args in "igi --size 512x512 --set vpls=64" \
                "igi --size 512x512 --set downsample=4 --set interleave=3 --set imperfect_visibility=1" \
                "radiosity --size 512x512" "direct --size 512x512" \
                "pathtracer --size 256x256 --spp 64" "hair --size 480x270 --spp 16" \
                "fog --size 512x384" \
                "fog --size 512x384 --set eye_height=1.2 --set eye_distance=9"; do
        name=$(echo "$args" | tr ' =' '__' | cut -c1-60)
        $R $B/bin/lucent render --sample $args --backend cuda --out "$out/$name.cuda.png" | tail -12
        $R $B/bin/lucent render --sample $args --backend cpu --out "$out/$name.cpu.png" > /dev/null
        compare "$out/$name.cpu.png" "$out/$name.cuda.png" "$args"
    done
    ;;
igi_quick)
    echo "== bench igi Sponza 800x600, 180 VPLs: reflection layer on (default) and off (the paper)"
    for layer in 1 0; do
        LUCENT_SCENE_PATH=/work/shared/scenes $R $B/bin/lucent bench igi --backend cuda \
            --scene bench/scenes/sponza-igi.json --frames 50 --vpls 180 --reflection-layer $layer
    done
    ;;
igi)
    echo "== bench igi: Cornell box and Sponza (3 point lights, two mirror pools), 800x600"
    $R $B/bin/lucent bench igi --backend cuda --scene cornell --frames 50
    LUCENT_SCENE_PATH=/work/shared/scenes $R $B/bin/lucent bench igi --backend cuda \
        --scene bench/scenes/sponza-igi.json --frames 50
    LUCENT_SCENE_PATH=/work/shared/scenes $R $B/bin/lucent bench igi --backend cuda \
        --scene bench/scenes/sponza-igi.json --frames 50 --json > "$out/bench_igi_sponza.json"
    LUCENT_SCENE_PATH=/work/shared/scenes $R $B/bin/lucent render --sample igi --backend cuda \
        --scene bench/scenes/sponza-igi.json --size 800x600 --out "$out/igi_sponza.png" --repeat 50
    ;;
multi)
    # Several devices per launch (issue 8): the multi-device tests, the suites through the
    # multi-device path, images against one device, and the IGI scaling figure.
    gpus=$(nvidia-smi -L | wc -l)
    lists="0 0,0"; [ "$gpus" -ge 2 ] && lists="0 0,1 all"
    for list in $lists; do
        $R $B/bin/lucent render --sample igi --devices $list --size 1920x1080 --set vpls=180 \
            --out "$out/igi_devices_$list.exr" | tail -3
    done
    $R $B/bin/lucent render --sample igi --backend cuda --size 1920x1080 --set vpls=180 --out "$out/igi_one.exr" | tail -2
    for list in $lists; do
        cmp "$out/igi_one.exr" "$out/igi_devices_$list.exr" && echo "igi 1920x1080 --devices $list: identical file to one GPU"
    done
    echo "== bench igi 1920x1080, 180 VPLs: one GPU, then every list"
    for scene in cornell bench/scenes/sponza-igi.json; do
        LUCENT_SCENE_PATH=/work/shared/scenes $R $B/bin/lucent bench igi --backend cuda --scene $scene \
            --size 1920x1080 --vpls 180 --frames 30 --json > "$out/igi_scale_one_$(basename $scene .json).json"
        for list in $lists; do
            LUCENT_SCENE_PATH=/work/shared/scenes $R $B/bin/lucent bench igi --devices $list --scene $scene \
                --size 1920x1080 --vpls 180 --frames 30 --json > "$out/igi_scale_${list}_$(basename $scene .json).json"
        done
        python3 - "$out" "$(basename $scene .json)" $lists <<'PY'
import json, sys
out, scene, lists = sys.argv[1], sys.argv[2], sys.argv[3:]
one = json.load(open(f"{out}/igi_scale_one_{scene}.json"))
def fps(doc):
    return {r["configuration"]: r["fps"] for r in doc["rows"]}
base = fps(one)
for l in lists:
    got = fps(json.load(open(f"{out}/igi_scale_{l}_{scene}.json")))
    print(scene, "--devices", l, " ".join(f"{c}: {got[c]:.1f} fps ({got[c] / base[c]:.2f}x of {base[c]:.1f})" for c in base))
PY
    done
    echo "== multi_device_test ($gpus GPUs)"
    $R $B/bin/multi_device_test 2>&1 | tail -25
    for list in 0,0 cpu,0; do
        for t in ${MULTI_SUITES:-programs exceptions igi pathtracer}; do
            LUCENT_TEST_BACKEND=cuda LUCENT_TEST_DEVICES=$list $R $B/bin/${t}_test > "$work/md.log" 2>&1
            echo "${t}_test through --devices $list: $(grep -E '^\[  (PASSED|FAILED)  \]' "$work/md.log" | tr '\n' ' ')"
            grep -E '^\[  FAILED  \] [A-Z]' "$work/md.log" | head -5
        done
    done
    ;;
pathtracer)
    echo "== path tracer, Cornell box 1024x1024"
    $R $B/bin/lucent render --sample pathtracer --scene cornell --backend cuda --size 1024x1024 --spp 256 --out "$out/pathtracer_cornell.png"
    $R $B/bin/lucent render --sample pathtracer --scene cornell-materials --backend cuda --size 1024x1024 --spp 256 --out "$out/pathtracer_materials.png"
    ;;
fog)
    echo "== bench fog: the tutorial scene at 1024x768, moving camera (Sebald Table 1)"
    $R $B/bin/lucent bench fog --backend cuda --frames 100
    $R $B/bin/lucent bench fog --backend cuda --frames 100 --json > "$out/bench_fog.json"
    ;;
tea)
    echo "== bench tea on the GPU: the engine's launches read back (Table 2), then stream-ordered"
    $R $B/bin/lucent bench tea --backend cuda
    $R $B/bin/lucent bench tea --backend cuda --json > "$out/bench_tea.json"
    $R $B/bin/lucent bench tea --backend cuda --rounds 16
    echo "== bench tea --megabytes 5000 must be refused (the stream rows' limit)"
    $R $B/bin/lucent bench tea --backend cuda --megabytes 5000; echo "exit $?"
    ;;
sanitizer)
    echo "== compute-sanitizer memcheck: whitted, bench rays"
    compute-sanitizer --tool memcheck --print-limit 20 $R $B/bin/lucent render --sample whitted --backend cuda --size 256x256 --out "$out/whitted_sanitized.png" 2>&1 | tail -8
    compute-sanitizer --tool memcheck --print-limit 20 $R $B/bin/lucent bench rays --backend cuda --size 640x360 --repeat 1 --scene /work/shared/scenes/sponza.obj 2>&1 | tail -12
    ;;
sanitize)
    # compute-sanitizer on every sample and on the GPU test suites: SANITIZE_TOOLS (default
    # memcheck racecheck initcheck), SANITIZE_PARTS (samples suites), SANITIZE_SUITES (default:
    # every suite in the bundle), SANITIZE_JOBS runs at once (default 4: the tools' time is
    # mostly the host's instrumenting of each loaded kernel). Each run's error count goes to
    # $out/sanitize_summary.txt, its log (first reports) to $out/sanitize/; a run that ends
    # badly (exit other than 0) counts as failed.
    mkdir -p "$out/sanitize"
    summary="$out/sanitize_summary.txt"
    sanitized() {  # TOOL LABEL COMMAND...
        local tool=$1 label=$2; shift 2
        local log="$out/sanitize/$tool.$label.log" flags=""
        [ "$tool" = memcheck ] && flags="--leak-check full"
        [ "$tool" = racecheck ] && flags="--racecheck-report hazard"
        local t0=$SECONDS
        timeout 420 compute-sanitizer --tool "$tool" $flags --print-limit 10 --error-exitcode 86 \
            "$@" > "$log" 2>&1
        local rc=$?
        local errors
        errors=$(grep -hoE "ERROR SUMMARY: [0-9]+ error" "$log" | awk '{ n += $3 } END { print n + 0 }')
        local hazards
        hazards=$(grep -hoE "RACECHECK SUMMARY: [0-9]+ hazard" "$log" | awk '{ n += $3 } END { print n + 0 }')
        printf '%-10s %-44s exit %3d  errors %s  hazards %s  %4d s\n' "$tool" "$label" "$rc" \
            "$errors" "$hazards" $((SECONDS - t0)) | tee -a "$summary"
    }
    in_background() {  # sanitized ARGS... with at most SANITIZE_JOBS at once
        while [ "$(jobs -rp | wc -l)" -ge "${SANITIZE_JOBS:-4}" ]; do wait -n; done
        sanitized "$@" &
    }
    for tool in ${SANITIZE_TOOLS:-memcheck racecheck initcheck}; do
      for part in ${SANITIZE_PARTS:-samples suites}; do
        if [ "$part" = samples ]; then
          while read -r label args; do
            [ -n "$label" ] || continue
            in_background "$tool" "$label" $R $B/bin/lucent $args
          done <<SAMPLES
whitted render --sample whitted --backend cuda --size 128x128 --out $work/$tool-whitted.png
direct render --sample direct --backend cuda --scene cornell --size 128x128 --out $work/$tool-direct.png
igi render --sample igi --backend cuda --scene cornell --size 128x128 --set vpls=32 --out $work/$tool-igi.png
igi-accelerated render --sample igi --backend cuda --scene cornell --size 128x128 --set vpls=36 --set downsample=4 --set interleave=3 --set imperfect_visibility=1 --out $work/$tool-igi-accelerated.png
radiosity render --sample radiosity --backend cuda --scene cornell --size 128x128 --out $work/$tool-radiosity.png
pathtracer render --sample pathtracer --backend cuda --scene cornell --size 128x128 --spp 4 --out $work/$tool-pathtracer.exr --aov albedo,normal,depth,position,instance --denoise
fog render --sample fog --backend cuda --size 128x96 --out $work/$tool-fog.png
tea bench tea --backend cuda --megabytes 4
spheres bench spheres --backend cuda --count 2000 --size 128x128 --repeat 1
curves bench curves --backend cuda --segments 2000 --size 128x128 --repeat 1
SAMPLES
        else
          for t in ${SANITIZE_SUITES:-$(cd $B/bin && ls *_test | sed 's/_test$//')}; do
            LUCENT_TEST_BACKEND=cuda LUCENT_SOAK_LAUNCHES=60 in_background "$tool" "${t}_test" $R $B/bin/${t}_test
          done
        fi
      done
    done
    wait
    ;;
profile)
    echo "== ncu: the Whitted megakernel at 1024x1024"
    ncu --kernel-name regex:lucent_ray_generation_ --launch-skip 2 --launch-count 1 \
        --section SpeedOfLight --section Occupancy --section LaunchStats --section WarpStateStats \
        $R $B/bin/lucent render --sample whitted --backend cuda --size 1024x1024 --repeat 4 --out "$work/p.png" 2>&1 | grep -vE "^==PROF==|^ +-+$" | tail -80
    ;;
profile_igi)
    echo "== ncu: the IGI indirect pass (canonical, 180 VPLs) on Sponza at 800x600"
    # Launches per frame: VPL generation, direct, indirect, composition; skip frame 1 and
    # the first two launches of frame 2.
    LUCENT_SCENE_PATH=/work/shared/scenes ncu --kernel-name regex:lucent_ray_generation_ --launch-skip 6 \
        --launch-count 1 --section SpeedOfLight --section Occupancy --section LaunchStats \
        --section WarpStateStats --section MemoryWorkloadAnalysis \
        $R $B/bin/lucent render --sample igi --backend cuda --scene bench/scenes/sponza-igi.json \
        --size 800x600 --repeat 3 --out "$work/p.png" 2>&1 | grep -vE "^==PROF==|^ +-+$" | tail -90
    ;;
profile_igi_pass)
    # One pass of an IGI frame with all three accelerations, Sponza 800x600, under ncu. Seven
    # launches a frame (VPL generation, direct, indirect, the sum of its VPL slices,
    # discontinuity, upsampling, composition); launches 1-3 of each entry try the launch
    # shapes, so frame 4 starts at launch 21: IGI_LAUNCH=22 (default) is its direct pass, 23
    # its indirect pass.
    echo "== ncu: IGI launch ${IGI_LAUNCH:-22} with all three accelerations, Sponza 800x600"
    LUCENT_SCENE_PATH=/work/shared/scenes LUCENT_NVRTC_OPTIONS="-lineinfo" ncu \
        --kernel-name regex:lucent_ray_generation_ --launch-skip ${IGI_LAUNCH:-22} --launch-count 1 \
        --section SpeedOfLight --section Occupancy --section LaunchStats --section WarpStateStats \
        --section SourceCounters -f -o $work/igi_pass \
        $R $B/bin/lucent render --sample igi --backend cuda --scene bench/scenes/sponza-igi.json \
        --size 800x600 --set imperfect_visibility=1 --set downsample=4 --set interleave=3 \
        --repeat 5 --out "$work/p.png" 2>&1 | tail -3
    ncu -i $work/igi_pass.ncu-rep --print-summary none 2>&1 | grep -vE "^==PROF==|^ +-+$" | \
        grep -E "Duration|Registers|Occupancy|Warp Cycles|Issued|Eligible|Stall|Block Limit|Threads|Grid" | head -40
    ;;
hotspots)
    echo "== ncu: per-source-line stall samples of the Whitted megakernel (source.csv, sass.csv)"
    LUCENT_NVRTC_OPTIONS="-lineinfo" ncu --kernel-name regex:lucent_ray_generation_ --launch-skip 2 --launch-count 1 \
        --section SourceCounters --section WarpStateStats -f -o $work/whitted \
        $R $B/bin/lucent render --sample whitted --backend cuda --size 1024x1024 --repeat 4 --out "$work/p.png" 2>&1 | tail -3
    ncu -i $work/whitted.ncu-rep --page source --print-source cuda --csv > "$out/source.csv" 2> "$out/source.err"
    ncu -i $work/whitted.ncu-rep --page source --print-source sass --csv > "$out/sass.csv" 2>> "$out/source.err"
    ls -la "$out"; head -c 600 "$out/source.err"
    ;;
bench)
    for s in sponza sibenik bunny dragon cornell/CornellBox-Original; do
        # The bare kernels and the engine path (--programs: issue 25's table).
        echo "== bench rays --backend cuda --programs $s"
        $R $B/bin/lucent bench rays --backend cuda --scene /work/shared/scenes/$s.obj --repeat 9 \
            --programs
        $R $B/bin/lucent bench rays --backend cuda --scene /work/shared/scenes/$s.obj --repeat 9 \
            --programs --json > "$out/rays-cuda-$(basename $s .obj).json"
    done
    $R $B/bin/lucent bench build --backend cuda --scene /work/shared/scenes/sponza.obj
    ;;
builder)
    echo "== the GPU BVH builder (H-PLOC) and refit: layouts against brute force"
    $R $B/bin/gpu_bvh_builder_test
    echo "== compute-sanitizer memcheck and racecheck on the builder tests"
    compute-sanitizer --tool memcheck --leak-check full $R $B/bin/gpu_bvh_builder_test --gtest_filter='*Small*:*Refit*:*Index*' 2>&1 | tail -4
    compute-sanitizer --tool racecheck $R $B/bin/gpu_bvh_builder_test --gtest_filter='*Small*' 2>&1 | tail -4
    for s in sponza sibenik dragon bunny; do
        echo "== bench build --backend cuda $s"
        $R $B/bin/lucent bench build --backend cuda --scene /work/shared/scenes/$s.obj --repeat 9
    done
    echo "== bench build --backend cuda: sponza cut twice (1.06M triangles)"
    $R $B/bin/lucent bench build --backend cuda --scene /work/shared/scenes/sponza.obj --subdivide 2 --repeat 9
    echo "== bench build --backend cuda: dragon cut twice (1.6M triangles)"
    $R $B/bin/lucent bench build --backend cuda --scene /work/shared/scenes/dragon.obj --subdivide 2 --repeat 9
    ;;
startup)
    # What a user waits for before the first frame: the direct sample on Sponza at 4K,
    # `compile + accel` and the first launch's GPU scene update itemized
    # (LUCENT_GPU_ACCEL_TIMES: programs, instances, nodes, layouts, buffer mirrors uploaded
    # or cleared, the kernels' preparation); the first run compiles its kernels cold.
    for round in cold warm warm warm; do
        [ "$round" = cold ] && cold_cache
        echo "== direct, sponza.obj, 3840x2160, $round kernel cache"
        LUCENT_GPU_ACCEL_TIMES=1 $R $B/bin/lucent render --sample direct --backend cuda \
            --scene /work/shared/scenes/sponza.obj --size 3840x2160 --repeat 5 --json \
            --out "$work/startup.exr" 2> "$work/startup.log" |
            python3 -c 'import json, sys; print("\n".join("%s %.3f ms [%s]" % (s["name"], s["ms"], s.get("note", "")) for s in json.load(sys.stdin)["stages"]))'
        grep "lucent:" "$work/startup.log"
    done
    ;;
python)
    # The Python module linked for this machine's python3 (another version than the build
    # machine's) from the tree's bindings and the bundle's objects; then its tests with
    # backend "cuda", and TriangleMesh on the BENCH.md rays beside `bench rays --backend cuda`.
    P=$B/python
    pkg=$work/lucent-python/lucent
    mkdir -p "$pkg"
    cp python/lucent/*.py "$pkg/"
    printf '#!/bin/sh\nexec %s %s "$@"\n' "$PWD/$R" "$PWD/$B/bin/lucent" > $work/lucent-cli
    chmod +x $work/lucent-cli
    ext=$(python3 -c 'import sysconfig; print(sysconfig.get_config_var("EXT_SUFFIX"))')
    echo "== linking the Python module for $(python3 --version) ($ext)"
    g++ -O2 -std=c++20 -shared -fPIC -fvisibility=hidden -DLUCENT_HAVE_CUDA=1 \
        -Ipython/src -I. -Isrc -Iinclude $(python3 -m pybind11 --includes) python/src/*.cpp \
        $P/objects/*.o -Wl,--start-group $P/lib/*.a -Wl,--end-group -Wl,-Bsymbolic-functions \
        $P/so/*.so* -ldl -lpthread -o "$pkg/_lucent$ext" 2>&1 | grep -v "warning: " | head -20
    export LD_LIBRARY_PATH=$PWD/$P/so PYTHONPATH=$work/lucent-python LUCENT_CLI=$work/lucent-cli
    export LUCENT_SCENES_DIR=/work/shared/scenes
    echo "== the Python tests on the GPU (LUCENT_TEST_BACKEND=cuda)"
    LUCENT_TEST_BACKEND=cuda python3 -m pytest -q -p no:cacheprovider python/tests 2>&1 | tail -25
    echo "== TriangleMesh on the BENCH.md rays of sponza on the GPU, beside bench rays --backend cuda"
    python3 examples/python/bench_rays.py --backend cuda \
        --scene /work/shared/scenes/sponza.obj --rounds 3
    ;;
present)
    echo "== display frames on the GPU: bit for bit the host's encoding"
    LUCENT_TEST_BACKEND=cuda $R $B/bin/display_test
    compute-sanitizer --tool memcheck --leak-check full $R $B/bin/display_test --gtest_filter='DisplayFrame.*' 2>&1 | tail -3
    echo "== the viewer's presentation path at 1920x1080 in a headless EGL context"
    $R $B/bin/lucent bench present --backend cuda --frames 200
    $R $B/bin/lucent bench present --backend cuda --frames 200 --json > "$out/present_cuda.json"
    $R $B/bin/lucent bench present --backend cuda --sample pathtracer --frames 200
    ;;
esac
done
