#!/usr/bin/env bash
# Installs the Debian packages osr-vk builds and runs with, skipping those already present.
# Used by run.sh and test.sh; safe to run repeatedly.
set -euo pipefail
packages=(
  build-essential cmake ninja-build pkg-config python3
  libvulkan-dev mesa-vulkan-drivers vulkan-validationlayers vulkan-tools
  glslang-tools spirv-tools
  libglm-dev libtinygltf-dev nlohmann-json3-dev libstb-dev
  libopenexr-dev libimath-dev libglfw3-dev libimgui-dev
  xvfb xauth
  libgtest-dev libembree-dev
  python3-torch python3-numpy python3-hypothesis
  python3-distributed python3-dask
  slurm-wlm slurm-client munge
  blender
)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]})); then
  echo "osr-vk: installing ${missing[*]}" >&2
  sudo=""
  [ "$(id -u)" -eq 0 ] || sudo="sudo"
  $sudo apt-get update -q
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -q --no-install-recommends "${missing[@]}"
fi
