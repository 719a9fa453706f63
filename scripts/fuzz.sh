#!/usr/bin/env bash
# Builds the libFuzzer targets with clang (ASan + UBSan) in build-fuzz/ and
# runs them for SECONDS in all (default 60): half for the whole plant chain
# (grammar -> turtle -> mesh -> every exporter, seeded with grammars/), a
# sixth each for the grammar front end, the OBJ reader (seeded with
# grammars/surfaces) and cpfg's side files (contours, curves, background
# scenes; the first byte picks the reader). Inputs up to 64 KiB.
set -euo pipefail
cd "$(dirname "$0")/.."
seconds="${1:-60}"
scripts/deps.sh --fuzz
CC=clang CXX=clang++ cmake -S . -B build-fuzz -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DSYLVA_BUILD_TESTS=OFF -DSYLVA_BUILD_BENCH=OFF -DSYLVA_BUILD_EXAMPLES=OFF -DSYLVA_BUILD_FUZZ=ON \
  -DCMAKE_CXX_FLAGS="-fsanitize=address,undefined -fno-sanitize-recover=all -fsanitize=fuzzer-no-link" \
  >/dev/null
cmake --build build-fuzz -j"$(nproc)" --target fuzz_grammar fuzz_obj fuzz_plant fuzz_cpfg_files
mkdir -p build-fuzz/corpus/grammar build-fuzz/corpus/obj build-fuzz/corpus/plant \
  build-fuzz/corpus/cpfg_files
find grammars -name '*.lsys' -exec cp {} build-fuzz/corpus/grammar/ \;
find grammars -name '*.lsys' -exec cp {} build-fuzz/corpus/plant/ \;
find grammars -name '*.obj' -exec cp {} build-fuzz/corpus/obj/ \;
# A seed that uses the in-memory file system: an include and a surface.
printf 'axiom: A\n#include "r.lsys"\n#file r.lsys\nA --> F[+A~s]F[-A]\n#file s.obj\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n' \
  > build-fuzz/corpus/plant/seed_files.lsys
# One seed a reader: '0' a contour, '1' a curve, '2' a background scene.
printf '0cver 1 3\nname: c\npoints: 4 6\ntype: cr\nsamples: 8\n-1 0 0 3\n0 1 0 1\n1 0 0 1\n0 -1 0 1\n' \
  > build-fuzz/corpus/cpfg_files/contour
printf '1points: 4\ndimension: 4\ntype: bspline-endpoint\n0 0 0 3\n1 0 0 1\n2 1 0 1\n3 1 0 3\n' \
  > build-fuzz/corpus/cpfg_files/curve
printf '2#define W 2\nmaterial 0 0 0 1 .5 .5 .5 1\npushmatrix\ntranslate 1 2 3\nbox W 1 1 /* c */\npopmatrix\ncylinder 1 2\nsphere 1\n' \
  > build-fuzz/corpus/cpfg_files/background
run() {  # target seconds
  echo "== $1 for $2 s"
  build-fuzz/tests/fuzz/"$1" build-fuzz/corpus/"${1#fuzz_}" -max_total_time="$2" -max_len=65536 \
    -timeout=10 -rss_limit_mb=2048 -print_final_stats=1 -artifact_prefix=build-fuzz/"$1"- 2>&1 | tail -n 12
}
sixth=$((seconds / 6))
run fuzz_plant "$((seconds - 3 * sixth))"
run fuzz_grammar "$sixth"
run fuzz_obj "$sixth"
run fuzz_cpfg_files "$sixth"
