#!/usr/bin/env bash
# Writes scenes as glTF with `sylva mesh scene.xml` and checks every file
# with the Khronos glTF validator (npm gltf-validator, run with node): zero
# errors and zero warnings. The 50-tree forest (tests/scene/data/forest50.xml)
# as .glb and .gltf, an empty scene, and each example scene at a time when its particles,
# cloth or boids are in the air.
# Usage: validate_scene_exports.sh SYLVA_BINARY SOURCE_DIR WORK_DIR
set -euo pipefail
sylva="$1"; src="$2"; work="$3"
mkdir -p "$work"
# Installed by scripts/deps.sh (the set-up commands), never downloaded here.
tools="$src/tools"
if [[ ! -d "$tools/node_modules/gltf-validator" ]]; then
  echo "FAIL: the glTF validator is not installed: run scripts/deps.sh"
  exit 1
fi
fail=0
files=()
export_scene() {  # scene output time
  rm -f "$2"
  if "$sylva" mesh "$1" -o "$2" --time "$3" --threads 2; then files+=("$2"); else
    echo "FAIL: sylva mesh $1 -o $2 --time $3"; fail=1; fi
}
export_scene "$src/tests/scene/data/forest50.xml" "$work/forest50.glb" 1
export_scene "$src/tests/scene/data/forest50.xml" "$work/forest50.gltf" 1
export_scene "$src/examples/scenes/fireworks.xml" "$work/fireworks.glb" 3
export_scene "$src/examples/scenes/flock.xml" "$work/flock.glb" 1
export_scene "$src/examples/scenes/flag.xml" "$work/flag.glb" 1
export_scene "$src/examples/scenes/autumn.xml" "$work/autumn.glb" 2
export_scene "$src/examples/scenes/snowy_forest.xml" "$work/snowy_forest.glb" 2
# A scene with nothing to draw is a valid empty glTF scene.
printf '<scene version="1">\n  <camera position="1 1 1" target="0 0 0"/>\n</scene>\n' >"$work/empty.xml"
export_scene "$work/empty.xml" "$work/empty.glb" 0
NODE_PATH="$tools/node_modules" node "$src/tests/tools/validate_gltf.js" "${files[@]}" || fail=1
exit $fail
