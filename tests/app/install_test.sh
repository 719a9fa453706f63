#!/usr/bin/env bash
# Installs this build into a scratch prefix, then builds examples/consumer
# (an out-of-tree project: find_package(Sylva CONFIG)) against it and runs
# it; also runs the installed `sylva` with no source tree to lean on.
# Usage: install_test.sh BUILD_DIR SOURCE_DIR WORK_DIR [CXX_FLAGS [LINKER_FLAGS]]
# (the flags of the build, so a sanitizer build's consumer links its runtime)
set -euo pipefail
build="$1"; src="$2"; work="$3"; cxxflags="${4:-}"; ldflags="${5:-}"
rm -rf "$work"; mkdir -p "$work"
cmake --install "$build" --prefix "$work/prefix" >/dev/null
test -f "$work/prefix/include/sylva/plant/plant.h"
test -f "$work/prefix/include/sylva/terrain/height_field.h"
test -f "$work/prefix/lib/cmake/Sylva/SylvaConfig.cmake"
cmake -S "$src/examples/consumer" -B "$work/consumer" -DCMAKE_PREFIX_PATH="$work/prefix" \
  -DCMAKE_BUILD_TYPE=Release -DCMAKE_CXX_FLAGS="$cxxflags" -DCMAKE_EXE_LINKER_FLAGS="$ldflags" >/dev/null
cmake --build "$work/consumer" -j2 >/dev/null
cp "$src/grammars/plants/leafy_stem.lsys" "$work/stem.lsys"  # uses the bundled ~leaf and ~flower
"$work/consumer/plant_to_obj" "$work/stem.lsys" "$work/stem.obj"
grep -q "^f " "$work/stem.obj"
# The installed command finds its data (surfaces) under share/sylva.
"$work/prefix/bin/sylva" mesh "$work/stem.lsys" -o "$work/stem2.glb" 2>/dev/null
test -s "$work/stem2.glb"
echo "installed, consumer built and ran, installed sylva works"
