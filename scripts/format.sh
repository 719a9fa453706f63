#!/usr/bin/env bash
# clang-format over every C++ file of the project (.clang-format).
# Usage: scripts/format.sh          formats in place
#        scripts/format.sh --check  lists the files that differ; exit 1 if any
set -euo pipefail
cd "$(dirname "$0")/.."
mapfile -t files < <(git ls-files '*.cpp' '*.h' '*.inl' ':!:tests/fuzz/corpus/*')
if [[ "${1:-}" == "--check" ]]; then
  bad=0
  for f in "${files[@]}"; do
    if ! clang-format --dry-run --Werror "$f" >/dev/null 2>&1; then echo "not formatted: $f"; bad=1; fi
  done
  exit $bad
fi
clang-format -i "${files[@]}"
