#!/usr/bin/env bash
# The main job on a bundled default: install what is missing, build, and
# derive ABOP's monopodial tree (Fig. 2.6a), printing its statistics.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/deps.sh
scripts/build.sh
build/src/app/sylva derive grammars/abop/fig2_06a_monopodial.lsys --stats
