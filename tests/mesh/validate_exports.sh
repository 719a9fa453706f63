#!/usr/bin/env bash
# Writes meshes of catalogue plants in every format with `sylva mesh` and
# checks them with the formats' own tools:
#  - the Khronos glTF validator (npm gltf-validator, run with node): zero
#    errors and zero warnings for every .glb and .gltf;
#  - `assimp info -r` (raw import, Debian assimp-utils): the face count that
#    sylva reported, and the vertex count the format implies (PLY and
#    single-material glTF: exact; OBJ: 3 per face, as assimp expands corners).
# Usage: validate_exports.sh SYLVA_BINARY SOURCE_DIR WORK_DIR
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
check() {  # what expected actual
  if [[ "$2" != "$3" ]]; then echo "FAIL: $1: expected $2, got $3"; fail=1; else echo "ok: $1 = $3"; fi
}
gltfs=()
for plant in abop/fig2_06a_monopodial abop/fig1_25_bush abop/fig1_24c_bracketed_plant plants/leafy_stem; do
  for ext in obj ply glb gltf; do
    out="$work/$(basename $plant).$ext"
    rm -f "$out"
    summary=$("$sylva" mesh "$src/grammars/$plant.lsys" --sides 6 -o "$out" 2>&1 >/dev/null | head -1)
    verts=$(sed -E 's/.*: ([0-9]+) vertices, ([0-9]+) triangles.*/\1/' <<<"$summary")
    faces=$(sed -E 's/.*: ([0-9]+) vertices, ([0-9]+) triangles.*/\2/' <<<"$summary")
    info=$(assimp info "$out" -r 2>&1)
    av=$(awk '/^Vertices:/{print $2}' <<<"$info")
    af=$(awk '/^Faces:/{print $2}' <<<"$info")
    nm=$(awk '/^Meshes:/{print $2; exit}' <<<"$info")
    check "$(basename $plant).$ext faces" "$faces" "$af"
    case $ext in
      obj) check "$(basename $plant).$ext vertices" "$((3 * faces))" "$av" ;;
      ply) check "$(basename $plant).$ext vertices" "$verts" "$av" ;;
      glb|gltf) check "$(basename $plant).$ext vertices" "$((verts * nm))" "$av"; gltfs+=("$out") ;;
    esac
  done
done
NODE_PATH="$tools/node_modules" node "$src/tests/tools/validate_gltf.js" "${gltfs[@]}" || fail=1
exit $fail
