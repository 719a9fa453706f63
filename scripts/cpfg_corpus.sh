#!/usr/bin/env bash
# Runs `sylva check` and `sylva render` on every cpfg file (.l) under DIR and
# prints one row per file: the exit status of each, the number of warnings,
# and the first error; then the totals.
#
#   scripts/cpfg_corpus.sh DIR [OUT]
#
# OUT (default /tmp/cpfg_corpus) receives one PNG per file that renders, named
# after its path under DIR with '/' turned into '__', and the full stderr of
# each run beside it (.log), so the pictures can be looked at afterwards.
# Files that are not L-systems (vlab control panels named *.l begin with
# "panel name:") are listed as "panel" and left out of the totals.
# Environment: SYLVA (the binary, default build/src/app/sylva), TIMEOUT
# (seconds per command, default 60), SIZE (default 480x360).
set -uo pipefail
if [[ $# -lt 1 || ! -d $1 ]]; then
  echo "usage: $0 DIR [OUT]" >&2
  exit 2
fi
dir=$(cd "$1" && pwd)
out=${2:-/tmp/cpfg_corpus}
here=$(cd "$(dirname "$0")/.." && pwd)
sylva=${SYLVA:-$here/build/src/app/sylva}
limit=${TIMEOUT:-60}
size=${SIZE:-480x360}
mkdir -p "$out"

files=0 checked=0 rendered=0 clean=0 panels=0 timeouts=0
printf '%-72s %5s %6s %5s  %s\n' file check render warn "first error"
while IFS= read -r -d '' f; do
  rel=${f#"$dir"/}
  if head -c 200 "$f" | grep -q '^panel name:'; then
    printf '%-72s %5s %6s %5s  %s\n' "$rel" - - - "panel (not an L-system)"
    panels=$((panels + 1))
    continue
  fi
  files=$((files + 1))
  stem=${rel//\//__}
  stem=${stem%.l}
  timeout "$limit" "$sylva" check "$f" >"$out/$stem.check.log" 2>&1
  crc=$?
  timeout "$limit" "$sylva" render "$f" --size "$size" -o "$out/$stem.png" \
    >"$out/$stem.log" 2>&1
  rrc=$?
  [[ $crc -eq 0 ]] && checked=$((checked + 1))
  [[ $rrc -eq 0 ]] && rendered=$((rendered + 1))
  [[ $rrc -eq 124 ]] && timeouts=$((timeouts + 1))
  warns=$(grep -c ': warning: ' "$out/$stem.log")
  [[ $rrc -eq 0 && $warns -eq 0 ]] && clean=$((clean + 1))
  err=$(grep -m1 -E ': error: |^error' "$out/$stem.log" | sed "s|$dir/||" | cut -c1-150)
  [[ $rrc -eq 124 ]] && err="timeout after ${limit}s"
  printf '%-72s %5s %6s %5s  %s\n' "$rel" "$crc" "$rrc" "$warns" "$err"
done < <(find "$dir" -name '*.l' -type f -print0 | sort -z)

echo
echo "files: $files (panels left out: $panels)"
echo "check exit 0: $checked"
echo "render exit 0: $rendered (of them without warnings: $clean)"
echo "timeouts: $timeouts"
echo "pictures and logs: $out"
