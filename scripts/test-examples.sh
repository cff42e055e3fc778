#!/usr/bin/env bash
# Builds and runs the examples/ projects as a user would: against Lucent installed from
# BUILD_DIR into a fresh prefix.
#
#   scripts/test-examples.sh [--build-only] [--work-dir DIR] BUILD_DIR
#
# For each examples/*/ project: configure and build it against the prefix, then run it on
# the CPU (--backend cpu) and check its exit code and what it wrote; when the package has
# the CUDA backend (Lucent_HAS_CUDA in its LucentConfig.cmake) and NVRTC is present, run it
# again with --jit-check 90 (the GPU megakernel generated and compiled by NVRTC, no GPU
# needed) and check that the CPU's output did not change. Also checks that a bad argument
# exits with 2, and, when the package has MPI (Lucent_HAS_MPI) and mpirun is here, that
# across-ranks under `mpirun -np 3` writes the image of one process.
#
# Last, first-program is built again with Lucent as a FetchContent subproject (its
# find_package answered by the declaration), and must give the same image
# (LUCENT_EXAMPLES_SKIP_SUBPROJECT=1 skips this: it compiles Lucent's library again).
#
# --build-only (or LUCENT_EXAMPLES_BUILD_ONLY=1): install and build, run nothing.
# --work-dir DIR: install and build under DIR and keep it (the executables are
#   DIR/build/<example>/<example>); otherwise a temporary directory, removed on success.
# Exits non-zero, naming each failure, when anything fails.
set -uo pipefail

usage() {
  echo "usage: $0 [--build-only] [--work-dir DIR] BUILD_DIR" >&2
  exit 2
}
build_only=${LUCENT_EXAMPLES_BUILD_ONLY:-0}
work=""
build_dir=""
while [ $# -gt 0 ]; do
  case "$1" in
    --build-only) build_only=1 ;;
    --work-dir) [ $# -ge 2 ] || usage; work=$2; shift ;;
    -*) usage ;;
    *) [ -z "$build_dir" ] || usage; build_dir=$1 ;;
  esac
  shift
done
[ -n "$build_dir" ] || usage
[ -f "$build_dir/CMakeCache.txt" ] || { echo "$0: $build_dir is not a CMake build directory" >&2; exit 2; }
build_dir=$(cd "$build_dir" && pwd)
root=$(cd "$(dirname "$0")/.." && pwd)

keep_work=1
if [ -z "$work" ]; then
  work=$(mktemp -d "${TMPDIR:-/tmp}/lucent-examples.XXXXXX")
  keep_work=0
fi
mkdir -p "$work"
work=$(cd "$work" && pwd)
prefix=$work/prefix
export LUCENT_CACHE_DIR=$work/cache

failures=()
fail() {
  echo "FAIL: $*" >&2
  failures+=("$*")
}
now() { date +%s.%N; }
elapsed() { awk -v a="$1" -v b="$(now)" 'BEGIN { printf "%.1f s", b - a }'; }

# Runs "$@" with its output in $log, echoing it; false when it fails.
log=""
run() {
  local name=$1
  shift
  log=$work/logs/$name.log
  mkdir -p "$work/logs"
  local start
  start=$(now)
  echo "+ $*"
  "$@" > "$log" 2>&1
  local rc=$?
  sed 's/^/    /' "$log"
  echo "  ($name: exit $rc, $(elapsed "$start"))"
  return $rc
}

# The width and height of a PNG (from its IHDR chunk), or nothing when it is not a PNG.
png_size() {
  [ "$(head -c 8 "$1" 2>/dev/null | od -An -tx1 | tr -d ' \n')" = 89504e470d0a1a0a ] || return 1
  od -An -tu1 -j16 -N8 "$1" |
    awk '{ printf "%dx%d\n", (($1*256+$2)*256+$3)*256+$4, (($5*256+$6)*256+$7)*256+$8 }'
}
# The number after "$2" on the line of $1's log that contains it.
field() { grep -o -- "$2 *[0-9.]*" "$1" | head -1 | awk '{ print $NF }'; }

# ---- install ------------------------------------------------------------------------
start=$(now)
if ! cmake --install "$build_dir" --prefix "$prefix" > "$work/install.log" 2>&1; then
  cat "$work/install.log" >&2
  echo "FAIL: cmake --install $build_dir --prefix $prefix" >&2
  exit 1
fi
echo "installed $build_dir into $prefix ($(elapsed "$start"))"
config=$(find "$prefix" -name LucentConfig.cmake | head -1)
has_cuda=0
if [ -n "$config" ] && grep -Eq '^ *set\(Lucent_HAS_CUDA +(ON|TRUE|1)\)' "$config"; then
  has_cuda=1
fi
nvrtc=0
if compgen -G "/usr/local/cuda/lib64/libnvrtc.so*" > /dev/null || [ -n "${LUCENT_NVRTC:-}" ]; then
  nvrtc=1
fi
jit_check=0
if [ "$has_cuda" = 1 ] && [ "$nvrtc" = 1 ]; then
  jit_check=1
  echo "the package has the CUDA backend and NVRTC is present: each example is also run with --jit-check 90"
else
  echo "no JIT check: Lucent_HAS_CUDA=$has_cuda, NVRTC found=$nvrtc"
fi

has_mpi=0  # the package spans MPI ranks and mpirun is here: across-ranks also runs under it
if [ -n "$config" ] && grep -Eq '^ *set\(Lucent_HAS_MPI +(ON|TRUE|1)\)' "$config" &&
   command -v mpirun > /dev/null; then
  has_mpi=1
fi

generator=()
if command -v ninja > /dev/null; then generator=(-G Ninja); fi

# ---- each example: build, run, check -------------------------------------------------
# Checks an example's output for plausibility; $1 = name, $2 = its log, $3 = its output.
check_output() {
  local name=$1 log=$2 out=$3 size
  case "$name" in
    first-program | across-ranks)
      size=$(png_size "$out") || { fail "$name: $out is not a PNG"; return; }
      [ "$size" = 640x480 ] || fail "$name: $out is $size, expected 640x480"
      local lit
      lit=$(field "$log" "covers")
      [ -n "$lit" ] && [ "$lit" -gt 1000 ] && [ "$lit" -lt 307200 ] ||
        fail "$name: the triangle covers '$lit' pixels, expected between 1000 and 307200"
      ;;
    ray-queries)
      local visible hits lines
      visible=$(grep -o 'line of sight: [0-9]* of [0-9]*' "$log" | awk '{ print $4, $6 }')
      hits=$(grep -o 'distance: [0-9]* of [0-9]*' "$log" | awk '{ print $2, $4 }')
      read -r v vt <<< "$visible"
      read -r h ht <<< "$hits"
      [ -n "${v:-}" ] && [ "$v" -gt 0 ] && [ "$v" -lt "$vt" ] ||
        fail "$name: '$visible' visible pairs (visible of total), expected 0 < visible < total"
      [ -n "${h:-}" ] && [ "$h" -gt 0 ] && [ "$h" -lt "$ht" ] ||
        fail "$name: '$hits' rays hit (hits of total), expected 0 < hits < total"
      lines=$(wc -l < "$out" 2>/dev/null || echo 0)
      [ "$lines" -eq $((vt + ht + 3)) ] 2>/dev/null ||
        fail "$name: $out has $lines lines, expected $((vt + ht + 3))"
      # scene::TriangleMesh, the same queries as arrays: every answer the programs' answer.
      local same
      same=$(grep -o '): [0-9]* of [0-9]* answers the same' "$log" | awk '{ print $2, $4 }')
      read -r s st <<< "$same"
      [ -n "${s:-}" ] && [ "$s" = "$st" ] && [ "$st" = $((vt + ht)) ] ||
        fail "$name: TriangleMesh gave '$same' (same of total) answers, expected all $((vt + ht))"
      ;;
    render-sample)
      # The README's main job (IGI, 64 VPLs, the Cornell box, 512x512) through
      # Lucent::samples: the same image, byte for byte, as the installed CLI renders.
      size=$(png_size "$out") || { fail "$name: $out is not a PNG"; return; }
      [ "$size" = 512x512 ] || fail "$name: $out is $size, expected 512x512"
      local cli_out=${out%.png}-cli.png
      if "$prefix/bin/lucent" render --sample igi --scene cornell --size 512x512 --set vpls=64 \
           --backend cpu --out "$cli_out" > "$work/logs/$name-cli.log" 2>&1; then
        cmp -s "$out" "$cli_out" || fail "$name: its image differs from \`lucent render\`'s ($cli_out)"
      else
        fail "$name: the installed lucent render failed (log: $work/logs/$name-cli.log)"
      fi
      # Another sample, from its own scene and defaults, as `lucent render` renders it.
      if "$bin" --sample whitted --size 96x64 --backend cpu --out "$work/out/$name-whitted.png" \
           > /dev/null 2>&1 &&
         "$prefix/bin/lucent" render --sample whitted --size 96x64 --backend cpu \
           --out "$work/out/$name-whitted-cli.png" > /dev/null 2>&1; then
        cmp -s "$work/out/$name-whitted.png" "$work/out/$name-whitted-cli.png" ||
          fail "$name --sample whitted: its image differs from \`lucent render --sample whitted\`'s"
      else
        fail "$name --sample whitted, or the installed lucent render of it, failed"
      fi
      "$bin" --sample igi --set vpls=0 --out "$work/out/$name-bad.png" > /dev/null 2>&1
      local rc=$?
      [ $rc -eq 2 ] || fail "$name --set vpls=0: exit $rc, expected 2 (out of the option's range)"
      [ ! -e "$work/out/$name-bad.png" ] || fail "$name --set vpls=0 wrote an image"
      ;;
    bench-rays)
      # `lucent bench rays --json` as a call (Lucent::bench): the installed CLI on the same
      # scene and rays must count the same hits at the same distances (the checksums; the
      # timings differ from run to run), and every engine agree.
      local cli_json=$work/out/$name-cli.json
      if "$prefix/bin/lucent" bench rays --scene "$root/examples/bench-rays/room.obj" \
           --size 320x240 --repeat 1 --json > "$cli_json" 2> "$work/logs/$name-cli.log"; then
        python3 - "$out" "$cli_json" <<'PY' || fail "$name: its document disagrees with the CLI's (above)"
import json, sys
mine, cli = (json.load(open(f)) for f in sys.argv[1:])
wrong = []
for kind, count in (("primary", "hits"), ("shadow", "occluded"), ("diffuse", "hits")):
    for key in (count, "sum_t"):
        if key in cli["lucent"][kind] and mine["lucent"][kind].get(key) != cli["lucent"][kind][key]:
            wrong.append(f"{kind} {key}: {mine['lucent'][kind].get(key)} against the CLI's {cli['lucent'][kind][key]}")
if mine.get("checksums_agree") is False:
    wrong.append("Lucent's and Embree's checksums differ")
if not mine.get("streams", {}).get("checksums_agree_with_kernels", False):
    wrong.append("the streams' checksums differ from the kernels'")
for w in wrong:
    print("   ", w)
sys.exit(1 if wrong else 0)
PY
      else
        fail "$name: the installed lucent bench rays failed (log: $work/logs/$name-cli.log)"
      fi
      grep -q "^primary " "$log" || fail "$name: no primary row in its table"
      # Its build line (bench_build_json) against the installed `lucent bench build --json`:
      # the same tree, so the same SAH cost and node count.
      local build_json=$work/out/$name-build-cli.json
      if "$prefix/bin/lucent" bench build --scene "$root/examples/bench-rays/room.obj" --repeat 1 \
           --no-peer --json > "$build_json" 2> "$work/logs/$name-build-cli.log"; then
        local expected
        expected=$(python3 -c 'import json, sys; d = json.load(open(sys.argv[1])); print("sah_cost %s, %s wide nodes" % (d["sah_cost"], d["wide_nodes"]))' "$build_json")
        grep -q "^build .*$expected" "$log" ||
          fail "$name: its build line is not the CLI's tree ('$expected'): $(grep '^build' "$log")"
      else
        fail "$name: the installed lucent bench build failed (log: $work/logs/$name-build-cli.log)"
      fi
      "$bin" --scene "$work/out/no-such-scene.obj" > /dev/null 2>&1
      local rc=$?
      [ $rc -eq 1 ] || fail "$name --scene (missing file): exit $rc, expected 1"
      ;;
    ambient-occlusion)
      size=$(png_size "$out") || { fail "$name: $out is not a PNG"; return; }
      [ "$size" = 640x480 ] || fail "$name: $out is $size, expected 640x480"
      local mean
      mean=$(field "$log" "mean value")
      awk -v m="${mean:-0}" 'BEGIN { exit !(m > 0.1 && m < 0.99) }' ||
        fail "$name: mean value '$mean', expected between 0.1 and 0.99"
      ;;
    *)
      [ -s "$out" ] || fail "$name: wrote nothing to $out"
      ;;
  esac
}

for dir in "$root"/examples/*/; do
  dir=${dir%/}
  name=$(basename "$dir")
  [ -f "$dir/CMakeLists.txt" ] || continue
  echo
  echo "==== $name"
  bin=$work/build/$name/$name
  if ! run "$name-configure" cmake -S "$dir" -B "$work/build/$name" "${generator[@]}" \
       -DCMAKE_BUILD_TYPE=Release -DCMAKE_PREFIX_PATH="$prefix"; then
    fail "$name: configure (log: $log)"
    continue
  fi
  if ! run "$name-build" cmake --build "$work/build/$name" -j"$(nproc)"; then
    fail "$name: build (log: $log)"
    continue
  fi
  [ -x "$bin" ] || { fail "$name: the build made no $bin"; continue; }
  [ "$build_only" = 1 ] && continue

  case "$name" in
    ray-queries) ext=txt ;;
    bench-rays) ext=json ;;
    *) ext=png ;;
  esac
  out=$work/out/$name.$ext
  mkdir -p "$work/out"
  if run "$name-cpu" "$bin" --backend cpu --out "$out"; then
    check_output "$name" "$log" "$out"
  else
    fail "$name --backend cpu (log: $log)"
  fi

  # across-ranks under mpirun (a package with MPI): three ranks give the image of one.
  if [ "$name" = across-ranks ] && [ "$has_mpi" = 1 ]; then
    mpi_out=$work/out/$name-3-ranks.$ext
    if run "$name-mpirun" mpirun --allow-run-as-root --oversubscribe -np 3 "$bin" \
         --backend cpu --out "$mpi_out"; then
      grep -q "^rank 2: " "$log" || fail "$name under mpirun -np 3: no share of rank 2 printed"
      cmp -s "$out" "$mpi_out" || fail "$name under mpirun -np 3: its image differs from one process's"
    else
      fail "$name under mpirun -np 3 (log: $log)"
    fi
  fi

  "$bin" --backend bogus > /dev/null 2>&1
  rc=$?
  [ $rc -eq 2 ] || fail "$name --backend bogus: exit $rc, expected 2"

  # bench-rays times the CPU's traversal and launches no megakernel there: no JIT check.
  if [ "$jit_check" = 1 ] && [ "$name" != bench-rays ]; then
    jit_out=$work/out/$name-jit.$ext
    if run "$name-jit-check" "$bin" --backend cpu --jit-check 90 --out "$jit_out"; then
      grep -q "jit-check: megakernel compiled for sm_90" "$log" ||
        fail "$name --jit-check 90: no 'jit-check: megakernel compiled' line"
      cmp -s "$out" "$jit_out" || fail "$name --jit-check 90: its output differs from the CPU run's"
    else
      fail "$name --backend cpu --jit-check 90 (log: $log)"
    fi
  fi
done

# ---- Lucent as a subproject: FetchContent (add_subdirectory underneath) ----------------
# first-program's own CMakeLists.txt, unchanged: its find_package(Lucent) is answered by the
# FetchContent declaration (OVERRIDE_FIND_PACKAGE), so the targets and lucent_add_programs
# come from Lucent's source tree instead of an installed package.
if [ "$build_only" = 0 ] && [ "${LUCENT_EXAMPLES_SKIP_SUBPROJECT:-0}" = 0 ]; then
  echo
  echo "==== first-program with Lucent as a FetchContent subproject"
  sub=$work/subproject
  mkdir -p "$sub"
  cat > "$sub/CMakeLists.txt" <<CMAKE
cmake_minimum_required(VERSION 3.25)
project(lucent_subproject_check LANGUAGES CXX)
include(FetchContent)
FetchContent_Declare(Lucent SOURCE_DIR "$root" OVERRIDE_FIND_PACKAGE)
FetchContent_MakeAvailable(Lucent)
add_subdirectory("$root/examples/first-program" first-program)
CMAKE
  if ! run subproject-configure cmake -S "$sub" -B "$sub/build" "${generator[@]}" \
       -DCMAKE_BUILD_TYPE=Release; then
    fail "subproject: configure (log: $log)"
  elif ! run subproject-build cmake --build "$sub/build" -j"$(nproc)" --target first-program; then
    fail "subproject: build (log: $log)"
  elif run subproject-run "$sub/build/first-program/first-program" --backend cpu \
       --out "$work/out/subproject.png"; then
    cmp -s "$work/out/subproject.png" "$work/out/first-program.png" ||
      fail "subproject: its image differs from the installed package's"
  else
    fail "subproject: first-program --backend cpu (log: $log)"
  fi
fi

echo
if [ ${#failures[@]} -gt 0 ]; then
  echo "${#failures[@]} failure(s); logs and outputs are in $work:" >&2
  printf '  %s\n' "${failures[@]}" >&2
  exit 1
fi
if [ "$build_only" = 1 ]; then
  echo "every example built; executables under $work/build"
else
  echo "every example built and ran"
fi
if [ "$keep_work" = 0 ] && [ "$build_only" = 0 ]; then
  rm -rf "$work"
else
  echo "work directory kept: $work"
fi
