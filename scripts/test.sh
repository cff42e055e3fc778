#!/usr/bin/env bash
# Installs the dependencies, builds Lucent into build/, runs every test with ctest, then
# installs the package and builds and runs examples/ against it.
set -euo pipefail
cd "$(dirname "$0")/.."

bash scripts/install-deps.sh
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release
cmake --build build -j"$(nproc)"
ctest --test-dir build --output-on-failure -j2
# The examples, built out of the tree against the installed package, as a user builds them.
bash scripts/test-examples.sh build
