#!/usr/bin/env bash
# Installs the Debian 12 packages Sylva needs, only those missing.
# Usage: scripts/deps.sh [--fuzz]   (--fuzz adds clang and its libFuzzer runtime)
set -euo pipefail
packages=(cmake g++ make pkg-config clang-format libeigen3-dev libcli11-dev libgtest-dev libbenchmark-dev python3
          libtinygltf-dev nlohmann-json3-dev libstb-dev assimp-utils libpugixml-dev libxml2-utils
          libegl-dev libgl-dev libglew-dev libgl1-mesa-dri libegl-mesa0
          libglfw3-dev libimgui-dev xvfb)
# node and npm run the Khronos glTF validator in the tests; any recent node will do.
command -v node >/dev/null 2>&1 || packages+=(nodejs)
command -v npm >/dev/null 2>&1 || packages+=(npm)
if [[ "${1:-}" == "--fuzz" ]]; then packages+=(clang libclang-rt-14-dev); fi
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]})); then
  echo "installing: ${missing[*]}"
  sudo=""
  [[ $(id -u) -ne 0 ]] && sudo="sudo"
  $sudo apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi

# The Khronos glTF validator for the export tests, into tools/ (not
# committed), once: the tests never download anything.
root="$(cd "$(dirname "$0")/.." && pwd)"
if [[ ! -d "$root/tools/node_modules/gltf-validator" ]]; then
  mkdir -p "$root/tools"
  (cd "$root/tools" && { [[ -f package.json ]] || npm init -y >/dev/null 2>&1; } &&
    npm install gltf-validator@2.0.0-dev.3.10 --no-audit --no-fund >/dev/null 2>&1) ||
    echo "warning: could not install the glTF validator (npm); the export test will fail"
fi
