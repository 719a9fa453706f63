#!/usr/bin/env bash
# Builds the libFuzzer target with clang (ASan + UBSan) in build-fuzz/ and
# runs it for SECONDS (default 60), seeded with every grammar in grammars/.
set -euo pipefail
cd "$(dirname "$0")/.."
seconds="${1:-60}"
scripts/deps.sh --fuzz
CC=clang CXX=clang++ cmake -S . -B build-fuzz -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DSYLVA_BUILD_TESTS=OFF -DSYLVA_BUILD_BENCH=OFF -DSYLVA_BUILD_FUZZ=ON \
  -DCMAKE_CXX_FLAGS="-fsanitize=address,undefined -fno-sanitize-recover=all -fsanitize=fuzzer-no-link" \
  >/dev/null
cmake --build build-fuzz -j"$(nproc)" --target fuzz_grammar
corpus=build-fuzz/corpus
mkdir -p "$corpus"
find grammars -name '*.lsys' -exec cp {} "$corpus/" \;
build-fuzz/tests/fuzz/fuzz_grammar "$corpus" -max_total_time="$seconds" -max_len=4096 \
  -timeout=10 -rss_limit_mb=2048 -print_final_stats=1 -artifact_prefix=build-fuzz/ 2>&1 | tail -n 25
