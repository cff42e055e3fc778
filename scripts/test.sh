#!/usr/bin/env bash
# Installs the dependencies, builds Lucent into build/, runs every test with ctest (the fuzz
# targets among them), installs the package and builds and runs examples/ against it, then
# builds the library and its CPU test suites with ASan + UBSan into build-asan/ and runs them
# (scripts/test-sanitized.sh). LUCENT_TEST_SANITIZED=0 leaves that last stage out (for a
# quicker run by hand; CI runs it). docs/testing.md has the stages and their times.
set -euo pipefail
cd "$(dirname "$0")/.."
# Each stage's wall time and CPU time (its processes' user + system seconds, from `times`):
# CPU time over wall time near 2 means the stage kept both cores of the CI machine busy.
times_file=$(mktemp)
trap 'rm -f "$times_file"' EXIT
cpu_now() {  # sets cpu: `times` run in this shell (a subshell would report its own)
  times > "$times_file"
  cpu=$(tail -1 "$times_file" | awk '{ split($1, u, /[ms]/); split($2, s, /[ms]/);
                                       printf "%d", u[1] * 60 + u[2] + s[1] * 60 + s[2] }')
}
cpu_now
started=$SECONDS cpu_started=$cpu
stage() {  # NAME
  cpu_now
  echo "test.sh: $1 took $((SECONDS - started)) s (CPU $((cpu - cpu_started)) s)"
  started=$SECONDS cpu_started=$cpu
}

bash scripts/install-deps.sh
stage install-deps
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release
cmake --build build -j"$(nproc)"
stage build
ctest --test-dir build --output-on-failure -j2
stage ctest
# The examples, built out of the tree against the installed package, as a user builds them.
bash scripts/test-examples.sh build
stage examples
if [ "${LUCENT_TEST_SANITIZED:-1}" != 0 ]; then
  bash scripts/test-sanitized.sh build-asan
  stage sanitized
fi
