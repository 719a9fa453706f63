#!/usr/bin/env bash
# Builds the libFuzzer targets with clang (ASan + UBSan) in build-fuzz/, then:
#
#   scripts/fuzz.sh                the reproducible check (CI, scripts/test.sh):
#                                  replays tests/fuzz/regressions/TARGET/, then
#                                  runs each target a fixed number of inputs
#                                  (-runs) from -seed=1 on a fresh corpus, so
#                                  the same commit finds the same thing on every
#                                  machine; about 72 s on a 2-core machine
#   scripts/fuzz.sh --hunt SECONDS [TARGET...]
#                                  long random hunting: replays the regressions,
#                                  then random seeds for SECONDS in all (split
#                                  over the targets named, default all four, as
#                                  below), on a corpus kept between hunts in
#                                  build-fuzz/hunt/TARGET
#
# The targets (tests/fuzz/): fuzz_plant, the whole plant chain (grammar ->
# turtle -> mesh -> every exporter, seeded with grammars/), half a hunt;
# a sixth each for fuzz_grammar (the grammar front end), fuzz_obj (the OBJ
# reader, seeded with grammars/surfaces) and fuzz_cpfg_files (cpfg's side
# files: contours, curves, background scenes; the first byte picks the
# reader). Inputs up to 64 KiB and 2 GiB of memory, 10 s each when hunting
# (60 s in the check, below).
#
# A finding is written to build-fuzz/TARGET-crash-* (or leak-, timeout-,
# oom-); `build-fuzz/tests/fuzz/TARGET FILE` replays it. Minimise it
# (`TARGET -minimize_crash=1 -runs=10000 FILE`), fix the cause with a test,
# and keep the input in tests/fuzz/regressions/TARGET/: the ctests
# Fuzz.*RegressionsReplayClean replay those in every build.
set -euo pipefail
cd "$(dirname "$0")/.."
hunt=0
if [[ "${1:-}" == "--hunt" ]]; then
  hunt=1
  seconds="${2:?usage: scripts/fuzz.sh --hunt SECONDS [TARGET...]}"
  shift 2
fi
targets=("$@")
((${#targets[@]})) || targets=(fuzz_plant fuzz_grammar fuzz_obj fuzz_cpfg_files)

scripts/deps.sh --fuzz
CC=clang CXX=clang++ cmake -S . -B build-fuzz -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DSYLVA_BUILD_TESTS=OFF -DSYLVA_BUILD_BENCH=OFF -DSYLVA_BUILD_EXAMPLES=OFF -DSYLVA_BUILD_FUZZ=ON \
  -DCMAKE_CXX_FLAGS="-fsanitize=address,undefined -fno-sanitize-recover=all -fsanitize=fuzzer-no-link" \
  -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O2 -gline-tables-only -DNDEBUG" \
  >/dev/null
cmake --build build-fuzz -j"$(nproc)" --target "${targets[@]}"

# The seed inputs of a target, in one order on every machine: the grammars
# (or surfaces) and tests/fuzz/seeds/TARGET/, sorted by path.
seed_files() {  # target
  {
    case "$1" in
      fuzz_grammar | fuzz_plant) find grammars -name '*.lsys' ;;
      fuzz_obj) find grammars -name '*.obj' ;;
    esac
    [[ -d tests/fuzz/seeds/$1 ]] && find tests/fuzz/seeds/"$1" -type f
  } | LC_ALL=C sort
}

# The reproducible check allows an input 60 s, not 10: a timeout is wall
# time, and on a loaded machine a slow input (fuzz_plant's -seed=1 path has
# one of 4 s CPU time) must not fail the check on one machine only.
options=(-max_len=65536 -timeout=10 -rss_limit_mb=2048)
((hunt)) || options=(-max_len=65536 -timeout=60 -rss_limit_mb=2048)

# The inputs that once found a bug, each once, before any fuzzing.
for t in "${targets[@]}"; do
  mapfile -t files < <(find tests/fuzz/regressions/"$t" -type f 2>/dev/null | LC_ALL=C sort)
  ((${#files[@]})) || continue
  echo "== $t: replaying ${#files[@]} regression inputs"
  if ! build-fuzz/tests/fuzz/"$t" "${options[@]}" -artifact_prefix=build-fuzz/"$t"- "${files[@]}" \
    >build-fuzz/"$t".log 2>&1; then
    tail -n 80 build-fuzz/"$t".log
    echo "FAIL: a regression input of $t fails again"
    exit 1
  fi
done

# What else steers a seeded run: libFuzzer reads a folder in the file
# system's order, which differs between machines, so the reproducible check
# gives it one folder a seed, named in order, after an empty folder that
# takes what it adds; it rereads that folder every second (-reload=0 turns
# that off); and the values it watches compared include addresses, which
# address-space randomisation changes each run (setarch -R turns it off for
# the fuzzer, where the system allows). Two runs of a target then add the
# same inputs in the same order.
norandom=()
setarch "$(uname -m)" -R true 2>/dev/null && norandom=(setarch "$(uname -m)" -R)
run() {  # target, then -runs=N or -max_total_time=S
  local t=$1 corpus
  local args=()
  if ((hunt)); then
    corpus=build-fuzz/hunt/"${t#fuzz_}"
    if [[ ! -d "$corpus" ]]; then
      mkdir -p "$corpus"
      seed_files "$t" | while read -r f; do cp "$f" "$corpus/$(echo "$f" | tr / _)"; done
    fi
    echo "== $t, random seed, $2"
  else
    corpus=build-fuzz/corpus/"${t#fuzz_}"
    rm -rf "$corpus" build-fuzz/seeds/"$t"
    mkdir -p "$corpus"
    local i=0 f dir
    while read -r f; do
      dir=$(printf 'build-fuzz/seeds/%s/%04d' "$t" "$i")
      mkdir -p "$dir" && cp "$f" "$dir"/ && args+=("$dir") && i=$((i + 1))
    done < <(seed_files "$t")
    args+=(-seed=1 -reload=0)
    echo "== $t, -seed=1, $2, $i seeds"
  fi
  local log=build-fuzz/"$t".log status=0
  local TIMEFORMAT="$t: %R s wall, %U s user + %S s system"
  local run=(build-fuzz/tests/fuzz/"$t")
  ((hunt)) || run=("${norandom[@]}" "${run[@]}")
  { time "${run[@]}" "$corpus" "${args[@]}" "$2" "${options[@]}" -print_final_stats=1 \
    -artifact_prefix=build-fuzz/"$t"- >"$log" 2>&1 || status=$?; } 2>build-fuzz/"$t".time
  if ((status)); then
    tail -n 80 "$log"
    echo "FAIL: $t found a bug (whole log: $log)"
    return 1
  fi
  grep -E '^(Done|stat::(new_units|slowest|peak))' "$log"
  cat build-fuzz/"$t".time
}

# Runs measured on a 2-core machine (Debian 12, clang 14), CPU time: 52 s
# for fuzz_plant (25 s of it its 50 seeds), 10 s fuzz_grammar, 7 s fuzz_obj,
# 3 s fuzz_cpfg_files. An idle machine runs them in about that wall time.
declare -A runs=([fuzz_plant]=250 [fuzz_grammar]=4000 [fuzz_obj]=20000 [fuzz_cpfg_files]=40000)
declare -A share=([fuzz_plant]=3 [fuzz_grammar]=1 [fuzz_obj]=1 [fuzz_cpfg_files]=1)
total_share=0
for t in "${targets[@]}"; do total_share=$((total_share + share[$t])); done
for t in "${targets[@]}"; do
  if ((hunt)); then
    run "$t" -max_total_time="$((seconds * share[$t] / total_share))"
  else
    run "$t" -runs="${runs[$t]}"
  fi
done
