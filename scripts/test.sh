#!/usr/bin/env bash
# Installs what is missing, builds, runs the fuzzers for FUZZ_SECONDS
# (default 60; 0 skips them), then every test (ctest), then the same suite
# in a build without graphics packages (NOGL=0 skips it) and under ASan and
# UBSan (SANITIZE=0 skips it). Each step's summary ends its output.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/deps.sh --fuzz
scripts/build.sh
if [[ "${FUZZ_SECONDS:-60}" != 0 ]]; then scripts/fuzz.sh "${FUZZ_SECONDS:-60}"; fi
(cd build && ctest --output-on-failure -j"$(nproc)")
if [[ "${NOGL:-1}" != 0 ]]; then scripts/test_nogl.sh; fi
if [[ "${SANITIZE:-1}" != 0 ]]; then scripts/sanitize.sh; fi
