#!/usr/bin/env bash
# The library and its CPU test suites built with AddressSanitizer and UndefinedBehavior-
# Sanitizer and run; any report fails the run (UBSan does not recover, ASan stops at the
# first error, LeakSanitizer reports leaks at exit). scripts/test.sh (CI) runs it after the
# Release build's tests; docs/testing.md has its stages and their times.
#
#   scripts/test-sanitized.sh [BUILD_DIR]     (default build-asan)
#
# The build is the CPU one (no CUDA backend, no Python module: the extension would need a
# sanitized interpreter), at -O1 with line tables only (gcc's -g1: reports name file:line,
# and the build is faster than at -g). Everything it builds is needed by the tests (the
# library, the samples, bench, the CLI that cli_test runs, the test executables). Not a unity
# build: the sources' anonymous namespaces share names (kRegistered, half_area, ...).
# Without MPI (LUCENT_MPI=OFF): Open MPI's own allocations at init and finalize are leaks to
# LeakSanitizer, and the build without MPI must keep compiling; so this stage builds and
# checks that configuration (mpi.library runs the distributed path with one rank), while
# the ctest stage runs the mpirun tests (docs/distributed.md, "Tests").
# Left out of the run, each for its reason:
#   fuzz.*                  the fuzz targets build their own sanitized binaries (ctest, Release)
#   accel_isa_symbols.*     counts the ISA variants' external symbols; instrumentation adds some
# TriangleAccelScenes.* (Sponza-sized scenes against brute force, minutes each when
# instrumented) run on LUCENT_SCENE_RAYS=40 rays instead of 700 where ../shared/scenes exists.
# The window and presentation tests run with leak detection off: Mesa's GL libraries, loaded
# and unloaded at run time, leave allocations LeakSanitizer cannot attribute; their memory
# errors are still caught. ccache is used when present (not in CI: it starts cold).
set -euo pipefail
cd "$(dirname "$0")/.."
build=${1:-build-asan}
started=$SECONDS
stage() {  # NAME: the time since the last stage, for the CI log
  echo "test-sanitized: $1 took $((SECONDS - started)) s"
  started=$SECONDS
}
sanitize="-fsanitize=address,undefined -fno-omit-frame-pointer -fno-sanitize-recover=undefined"
launcher=()
if command -v ccache > /dev/null; then
  launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache -DCMAKE_C_COMPILER_LAUNCHER=ccache)
fi
generator=()
command -v ninja > /dev/null && generator=(-G Ninja)
cmake -S . -B "$build" "${generator[@]}" "${launcher[@]}" -DCMAKE_BUILD_TYPE=Debug \
  -DCMAKE_CXX_FLAGS_DEBUG="-O1 -g1" -DCMAKE_C_FLAGS_DEBUG="-O1 -g1" \
  -DLUCENT_CUDA=OFF -DLUCENT_PYTHON=OFF -DLUCENT_MPI=OFF \
  "-DCMAKE_CXX_FLAGS=$sanitize" "-DCMAKE_C_FLAGS=$sanitize" \
  "-DCMAKE_EXE_LINKER_FLAGS=-fsanitize=address,undefined" \
  "-DCMAKE_SHARED_LINKER_FLAGS=-fsanitize=address,undefined"
cmake --build "$build" -j"$(nproc)"
stage build
export ASAN_OPTIONS=detect_leaks=1:abort_on_error=0:strict_string_checks=1:detect_stack_use_after_return=0
export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
export LUCENT_SCENE_RAYS=${LUCENT_SCENE_RAYS:-40}
gl='^(ViewTest|CliBenchPresent|Display)'
ctest --test-dir "$build" --output-on-failure -j2 -E "^fuzz\.|accel_isa_symbols|$gl"
# One at a time: two `xvfb-run -a` starting together race for a display and for their
# temporary directories ("problem while cleaning up temporary directory", exit 5 instead of
# the program's own), which the sanitized binaries' slow start-up makes likely.
ASAN_OPTIONS=${ASAN_OPTIONS/detect_leaks=1/detect_leaks=0} \
  ctest --test-dir "$build" --output-on-failure -j1 -R "$gl"
stage tests
