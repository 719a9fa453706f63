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
  # Best of three runs of each, as whole processes.
  best() { local b=999; for _ in 1 2 3; do local t0 t1; t0=$(date +%s.%N); "$@" > /dev/null; t1=$(date +%s.%N)
    b=$(python3 -c "print(min($b, $t1 - $t0))"); done; echo "$b"; }
  s1=$(best build/src/app/sylva derive "$grammar" -n "$n" --threads 1)
  s2=$(best build/src/app/sylva derive "$grammar" -n "$n")
  l=$(best node --max-old-space-size=8192 "$dir/lindenmayer_koch.js" "$n")
  python3 -c "print(f'n={$n}: lindenmayer.js {$l:.3f} s; sylva {$s1:.3f} s on 1 thread ({$l/$s1:.1f}x), {$s2:.3f} s on $(nproc) ({$l/$s2:.1f}x); $same')"
done
