#!/usr/bin/env bash
# Builds without any graphics package (SYLVA_BUILD_RENDER=OFF, which also
# turns the viewer off) in build-nogl/, and runs the tests of that build:
# the libraries, the GL-free command and its tests.
set -euo pipefail
cd "$(dirname "$0")/.."
cmake -S . -B build-nogl -DCMAKE_BUILD_TYPE=Release -DSYLVA_BUILD_RENDER=OFF -DSYLVA_BUILD_VIEWER=OFF \
  -DSYLVA_BUILD_BENCH=OFF -DSYLVA_BUILD_EXAMPLES=OFF >/dev/null
if grep -qiE "^(glfw3|GLEW|OpenGL)_DIR:|IMGUI_FOUND" build-nogl/CMakeCache.txt; then
  echo "FAIL: the build without the renderer looked for a graphics package"; exit 1
fi
cmake --build build-nogl -j"$(nproc)"
cd build-nogl
ctest --output-on-failure -j"$(nproc)" -LE source  # the format check ran in build/
