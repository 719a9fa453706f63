#!/usr/bin/env bash
# The whole ctest suite under AddressSanitizer and UndefinedBehaviorSanitizer
# (any report fails the test that triggered it), in build-asan/. The only
# suppressions are for third-party code, in tests/sanitizer/.
set -euo pipefail
cd "$(dirname "$0")/.."
# -O2 as RelWithDebInfo has it (the tests run faster than at -O1); -g1 keeps
# the line tables the reports need and compiles 2-3x faster than -g.
flags="-fsanitize=address,undefined -fno-sanitize-recover=undefined -fno-omit-frame-pointer"
cmake -S . -B build-asan -DCMAKE_BUILD_TYPE=RelWithDebInfo -DSYLVA_BUILD_BENCH=OFF \
  -DCMAKE_CXX_FLAGS="$flags" -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O2 -g1 -DNDEBUG" \
  -DCMAKE_EXE_LINKER_FLAGS="-fsanitize=address,undefined" >/dev/null
cmake --build build-asan -j"$(nproc)"
supp="$PWD/tests/sanitizer"
export ASAN_OPTIONS="detect_leaks=1:abort_on_error=0:halt_on_error=1"
export LSAN_OPTIONS="suppressions=$supp/lsan.supp:print_suppressions=0"
export UBSAN_OPTIONS="suppressions=$supp/ubsan.supp:print_stacktrace=1:halt_on_error=1"
cd build-asan
# Everything that does not draw, with LeakSanitizer; then what draws through
# Mesa (label "gl") without it: the driver is unloaded before the leak
# report, so its allocations carry no module name a suppression could match.
# (Label "source", the format check, ran in the Release build.)
ctest --output-on-failure -j"$(nproc)" -LE "gl|source"
ASAN_OPTIONS="detect_leaks=0:halt_on_error=1" ctest --output-on-failure -j"$(nproc)" -L gl
