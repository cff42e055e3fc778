#!/usr/bin/env bash
# Installs what Lucent needs to build and test on Debian 12. Idempotent: when every package
# is already installed it does not touch apt at all, so it is quick to run every time.
set -euo pipefail

packages=(
  build-essential cmake ninja-build pkg-config
  libgtest-dev libembree-dev libtinyobjloader-dev libtinygltf-dev libstb-dev libcli11-dev nlohmann-json3-dev
  libfftw3-dev libopenexr-dev clang libclang-rt-14-dev
  libglfw3-dev libimgui-dev libgl-dev libopengl-dev libegl-dev libegl-mesa0 libgl1-mesa-dri
  xvfb xauth
  pybind11-dev python3-dev python3-numpy python3-pytest
  openmpi-bin libopenmpi-dev
)

missing=()
for package in "${packages[@]}"; do
  if ! dpkg -s "$package" 2>/dev/null | grep -q '^Status: install ok installed'; then
    missing+=("$package")
  fi
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all ${#packages[@]} packages already installed"
  exit 0
fi

echo "install-deps: installing ${missing[*]}"
sudo_cmd=()
if [ "$(id -u)" -ne 0 ]; then
  if ! command -v sudo >/dev/null; then
    echo "install-deps: not root and no sudo; as root run: apt-get install ${missing[*]}" >&2
    exit 1
  fi
  sudo_cmd=(sudo)
fi
export DEBIAN_FRONTEND=noninteractive
"${sudo_cmd[@]}" apt-get update
"${sudo_cmd[@]}" apt-get install -y --no-install-recommends "${missing[@]}"
