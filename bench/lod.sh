#!/usr/bin/env bash
# Screen-space detail against issue 15's targets, ABOP Fig. 2.6a at n = 20,
# 1920x1080, default framing and a close-up (--camera 30,12,2.5):
#  - triangles with screen-space detail (--lod-eps 0.5, the default) against
#    uniform 16 sides (target: at most 10 %);
#  - SSIM of each picture against the reference (16 sides, --supersample 4):
#    target SSIM(lod) >= SSIM(uniform 16) - 0.005;
#  - whole-process `sylva render` time, screen-space against uniform 16,
#    with hyperfine (target: at most half);
#  - `sylva mesh --lod-eps 0.5 --size 1920x1080`: triangles, peak RSS, and
#    the Khronos validator when tools/node_modules has it.
# Usage: bench/lod.sh [BUILD_DIR] [WORK_DIR]
# Needs python3 with scikit-image (Debian python3-skimage) and hyperfine.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=${1:-$root/build}
work=${2:-/tmp/sylva-lod-bench}
sylva=$build/src/app/sylva
g=$root/grammars/abop/fig2_06a_monopodial.lsys
py=${PYTHON:-/usr/bin/python3}
runs=${RUNS:-3}
mkdir -p "$work"
common=(-n 20 --size 1920x1080)

stat() { grep "^$2:" "$work/$1.stats" | sed "s/^$2: //"; }
render() {  # name, flags...
  local name=$1
  shift
  /usr/bin/time -f "%M" -o "$work/$name.rss" \
    "$sylva" render "$g" "${common[@]}" --stats "$@" -o "$work/$name.png" \
    >"$work/$name.stats" 2>"$work/$name.err"
  printf '%-16s triangles %10s  tessellate %9s  draw %9s  total %9s  peak RSS %s MiB\n' "$name" \
    "$(stat "$name" triangles)" "$(stat "$name" tessellate)" "$(stat "$name" draw)" \
    "$(stat "$name" total)" "$(($(cat "$work/$name.rss") / 1024))"
}
ssim() {  # a b: SSIM over RGB, 8-bit
  "$py" - "$1" "$2" <<'PY'
import sys
import numpy as np
from skimage.io import imread
from skimage.metrics import structural_similarity
a = imread(sys.argv[1])[..., :3]
b = imread(sys.argv[2])[..., :3]
print(f"{structural_similarity(a, b, channel_axis=2, data_range=255):.4f}")
PY
}

echo "# sylva render ${common[*]} on $(basename "$g"); $(nproc) cores; $(date -u +%F)"
for view in default close; do
  cam=()
  [[ $view == close ]] && cam=(--camera 30,12,2.5)
  echo "## $view framing ${cam[*]}"
  render "$view-ref" --sides 16 --supersample 4 "${cam[@]}"
  render "$view-uniform16" --sides 16 "${cam[@]}"
  render "$view-lod" "${cam[@]}"
  lod=$(stat "$view-lod" triangles)
  uni=$(stat "$view-uniform16" triangles)
  su=$(ssim "$work/$view-uniform16.png" "$work/$view-ref.png")
  sl=$(ssim "$work/$view-lod.png" "$work/$view-ref.png")
  echo "triangles lod / uniform16: $(awk -v a="$lod" -v b="$uni" 'BEGIN{printf "%.2f %%", 100*a/b}') (target <= 10 %)"
  echo "SSIM vs reference: uniform16 $su, lod $sl (target lod >= $(awk -v s="$su" 'BEGIN{printf "%.4f", s-0.005}'))"
done

echo "## whole process, hyperfine --runs $runs"
hyperfine --runs "$runs" --export-markdown "$work/hyperfine.md" \
  -n uniform16 "$sylva render $g ${common[*]} --sides 16 -o $work/h-uniform.png" \
  -n lod "$sylva render $g ${common[*]} -o $work/h-lod.png" 2>&1 | grep -v '^ *$'

echo "## sylva mesh"
for mode in "--sides 16" "--lod-eps 0.5 --size 1920x1080"; do
  out=$work/mesh-$(echo "$mode" | tr -cd 'a-z0-9').glb
  # shellcheck disable=SC2086
  /usr/bin/time -f "%M %e" -o "$work/mesh.rss" "$sylva" mesh "$g" -n 20 $mode -o "$out" 2>"$work/mesh.err"
  read -r rss secs <"$work/mesh.rss"
  echo "mesh $mode: $(grep -o '[0-9]* triangles' "$work/mesh.err"), $(du -m "$out" | cut -f1) MB, peak RSS $((rss / 1024)) MiB, ${secs} s"
done
tools=${TOOLS:-$root/tools}
if [[ -d $tools/node_modules/gltf-validator ]]; then
  NODE_PATH=$tools/node_modules node "$root/tests/tools/validate_gltf.js" \
    "$work/mesh-lodeps05size1920x1080.glb" || true
fi
