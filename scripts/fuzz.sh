#!/usr/bin/env bash
# Builds the libFuzzer targets with clang (ASan + UBSan) in build-fuzz/ and
# runs them for SECONDS in all (default 60): half for the whole plant chain
# (grammar -> turtle -> mesh -> every exporter, seeded with grammars/), a
# quarter each for the grammar front end and the OBJ reader (seeded with
# grammars/surfaces). Inputs up to 64 KiB.
set -euo pipefail
cd "$(dirname "$0")/.."
seconds="${1:-60}"
scripts/deps.sh --fuzz
CC=clang CXX=clang++ cmake -S . -B build-fuzz -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DSYLVA_BUILD_TESTS=OFF -DSYLVA_BUILD_BENCH=OFF -DSYLVA_BUILD_EXAMPLES=OFF -DSYLVA_BUILD_FUZZ=ON \
  -DCMAKE_CXX_FLAGS="-fsanitize=address,undefined -fno-sanitize-recover=all -fsanitize=fuzzer-no-link" \
  >/dev/null
cmake --build build-fuzz -j"$(nproc)" --target fuzz_grammar fuzz_obj fuzz_plant
mkdir -p build-fuzz/corpus/grammar build-fuzz/corpus/obj build-fuzz/corpus/plant
find grammars -name '*.lsys' -exec cp {} build-fuzz/corpus/grammar/ \;
find grammars -name '*.lsys' -exec cp {} build-fuzz/corpus/plant/ \;
find grammars -name '*.obj' -exec cp {} build-fuzz/corpus/obj/ \;
# A seed that uses the in-memory file system: an include and a surface.
printf 'axiom: A\n#include "r.lsys"\n#file r.lsys\nA --> F[+A~s]F[-A]\n#file s.obj\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n' \
  > build-fuzz/corpus/plant/seed_files.lsys
run() {  # target seconds
  echo "== $1 for $2 s"
  build-fuzz/tests/fuzz/"$1" build-fuzz/corpus/"${1#fuzz_}" -max_total_time="$2" -max_len=65536 \
    -timeout=10 -rss_limit_mb=2048 -print_final_stats=1 -artifact_prefix=build-fuzz/"$1"- 2>&1 | tail -n 12
}
half=$((seconds / 2)); quarter=$((seconds / 4))
run fuzz_plant "$((seconds - 2 * quarter))"
run fuzz_grammar "$quarter"
run fuzz_obj "$quarter"
