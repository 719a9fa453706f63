#!/usr/bin/env bash
# Installs what is missing, builds, runs the grammar fuzzer for FUZZ_SECONDS
# (default 60; 0 skips it), then every test (ctest; its summary ends the output).
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/deps.sh --fuzz
scripts/build.sh
if [[ "${FUZZ_SECONDS:-60}" != 0 ]]; then scripts/fuzz.sh "${FUZZ_SECONDS:-60}"; fi
cd build
ctest --output-on-failure -j"$(nproc)"
