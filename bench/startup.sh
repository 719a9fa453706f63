#!/usr/bin/env bash
# Whole-process start-up of `sylva derive` (issue 14 targets), measured with
# hyperfine in one run so the ratios compare like with like:
#  1. a one-module grammar against /bin/true: within 2x;
#  2. ABOP Fig. 1.24a against lindenmayer.js 1.5.4 doing the same
#     derivation and printing the word: at least 10x faster. The issue says
#     "n=7 (4.9 M modules)"; n=7 is 195,311 modules and 4.9 M is n=9, so
#     both are measured.
# Installs hyperfine (apt) and lindenmayer (npm, into build/compare/) if
# missing. Writes bench/results/<date>-vm-startup.txt.
set -euo pipefail
cd "$(dirname "$0")/.."
command -v hyperfine >/dev/null || { sudo=""; [[ $(id -u) -ne 0 ]] && sudo=sudo;
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq hyperfine >/dev/null; }
dir=build/compare
mkdir -p "$dir"
if [[ ! -d "$dir/node_modules/lindenmayer" ]]; then
  (cd "$dir" && npm init -y >/dev/null && npm install lindenmayer@1.5.4 --no-audit --no-fund >/dev/null)
fi
cp bench/compare/lindenmayer_bracketed.js "$dir/"
sylva=build/src/app/sylva
one="$dir/one.lsys"
echo "axiom: F" > "$one"
g=grammars/abop/fig1_24a_bracketed_plant.lsys
for n in 7 9; do
  a=$("$sylva" derive "$g" -n $n | md5sum | cut -d' ' -f1)
  b=$(node --max-old-space-size=8192 "$dir/lindenmayer_bracketed.js" $n | md5sum | cut -d' ' -f1)
  [[ "$a" == "$b" ]] || { echo "the words differ at n=$n"; exit 1; }
done
md() { hyperfine -N --export-markdown "$dir/t.md" "$@" >/dev/null 2>&1; cat "$dir/t.md"; }
out=bench/results/$(date +%Y-%m-%d)-vm-startup.txt
{
  echo "# $(date -u +%FT%TZ) $(nproc) cores; sylva $(git rev-parse --short HEAD); identical words: yes"
  md --warmup 20 --runs 300 "/bin/true" "$sylva derive $one"
  for n in 7 9; do
    md --warmup 2 --runs 10 "$sylva derive $g -n $n --threads 1" "$sylva derive $g -n $n" \
      "node --max-old-space-size=8192 $dir/lindenmayer_bracketed.js $n"
  done
} | tee "$out"
