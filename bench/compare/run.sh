#!/usr/bin/env bash
# Whole-process comparison with lindenmayer.js 1.5.4 (npm) on ABOP Fig. 1.6:
# `sylva derive FILE -n N > /dev/null` against the same derivation in node.
# Installs lindenmayer@1.5.4 into build/compare/ (not committed). Prints one
# line per N: times, ratio, and checks that both words are identical.
set -euo pipefail
cd "$(dirname "$0")/../.."
dir=build/compare
mkdir -p "$dir"
if [[ ! -d "$dir/node_modules/lindenmayer" ]]; then
  (cd "$dir" && npm init -y >/dev/null && npm install lindenmayer@1.5.4 --no-audit --no-fund >/dev/null)
fi
cp bench/compare/lindenmayer_koch.js "$dir/"
grammar=grammars/abop/fig1_06_koch_island.lsys
for n in ${NS:-5 6 7}; do
  a=$(build/src/app/sylva derive "$grammar" -n "$n" | md5sum | cut -d' ' -f1)
  b=$(node --max-old-space-size=8192 "$dir/lindenmayer_koch.js" "$n" | md5sum | cut -d' ' -f1)
  same=$([[ "$a" == "$b" ]] && echo "identical words" || echo "WORDS DIFFER")
  t0=$(date +%s.%N); build/src/app/sylva derive "$grammar" -n "$n" --threads 1 > /dev/null; t1=$(date +%s.%N)
  node --max-old-space-size=8192 "$dir/lindenmayer_koch.js" "$n" > /dev/null; t2=$(date +%s.%N)
  python3 -c "s=$t1-$t0; l=$t2-$t1; print(f'n={$n}: sylva {s:.3f} s (1 thread), lindenmayer.js {l:.3f} s, ratio {l/s:.1f}x, $same')"
done
