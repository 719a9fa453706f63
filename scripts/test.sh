#!/usr/bin/env bash
# Installs what is missing, builds, runs the fuzzers' reproducible check
# (scripts/fuzz.sh: the regression inputs, then a fixed number of inputs
# from a fixed seed, about 60 s; FUZZ_SECONDS=N hunts with random seeds for
# N s instead, FUZZ_SECONDS=0 skips the fuzzers), then every test (ctest),
# then the same suite in a build without graphics packages (NOGL=0 skips it)
# and under ASan and UBSan (SANITIZE=0 skips it). Each step's summary ends
# its output.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/deps.sh --fuzz
scripts/build.sh
if [[ -z "${FUZZ_SECONDS:-}" ]]; then
  scripts/fuzz.sh
elif [[ "$FUZZ_SECONDS" != 0 ]]; then
  scripts/fuzz.sh --hunt "$FUZZ_SECONDS"
fi
(cd build && ctest --output-on-failure -j"$(nproc)")
if [[ "${NOGL:-1}" != 0 ]]; then scripts/test_nogl.sh; fi
if [[ "${SANITIZE:-1}" != 0 ]]; then scripts/sanitize.sh; fi
