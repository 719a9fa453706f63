#!/usr/bin/env bash
# The main job on a bundled default: install what is missing, build, derive
# ABOP's monopodial tree (Fig. 2.6a) printing its statistics, and write its
# mesh to out/monopodial.glb and a picture to out/monopodial.png (headless).
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/deps.sh
scripts/build.sh
build/src/app/sylva derive grammars/abop/fig2_06a_monopodial.lsys --stats
mkdir -p out
build/src/app/sylva mesh grammars/abop/fig2_06a_monopodial.lsys -o out/monopodial.glb
build/src/app/sylva render grammars/abop/fig2_06a_monopodial.lsys -o out/monopodial.png
