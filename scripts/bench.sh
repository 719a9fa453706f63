#!/usr/bin/env bash
# Runs the derivation benchmarks (3 repetitions, medians), the peak-memory
# check and the lindenmayer.js comparison; writes bench/results/<date>-<host>.txt
# and .json. Ratios, not bare times, are what compare across machines.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/deps.sh
scripts/build.sh -DSYLVA_BUILD_BENCH=ON
stamp="$(date +%Y-%m-%d)-$(hostname -s)"
out="bench/results/$stamp"
{
  echo "# Sylva derivation benchmarks, $(date -u +%Y-%m-%dT%H:%MZ)"
  echo "# machine: $(nproc) cores, $(lscpu | sed -n 's/^Model name: *//p'), $(free -g | awk '/Mem:/{print $2}') GiB"
  echo "# commit: $(git rev-parse --short HEAD)"
  echo
  build/bench/bench_derive --benchmark_repetitions=3 --benchmark_report_aggregates_only=true \
    --benchmark_out="$out.json" --benchmark_out_format=json 2>&1 | grep -E "^BM_.*_median" || true
  echo
  echo "# turtle interpretation (/0 fresh geometry, /1 reused), modules/s"
  build/bench/bench_turtle --benchmark_repetitions=3 --benchmark_report_aggregates_only=true 2>&1 \
    | grep -E "^BM_.*_median" || true
  echo
  echo "# peak memory, sylva derive fig1_06 (Koch) -n 8 > /dev/null (124.6 M modules)"
  /usr/bin/time -f "peak RSS %M KB, %e s" build/src/app/sylva derive grammars/abop/fig1_06_koch_island.lsys -n 8 \
    2>&1 >/dev/null
  echo
  echo "# whole process against lindenmayer.js 1.5.4 (node $(node --version 2>/dev/null || echo missing))"
  if command -v node >/dev/null && command -v npm >/dev/null; then
    NS="6 7 8" bench/compare/run.sh 2>/dev/null
  else
    echo "node/npm not installed: skipped"
  fi
} | tee "$out.txt"
# Median of 3 repetitions of each benchmark in program $1.
medians() {
  "$1" --benchmark_repetitions=3 --benchmark_report_aggregates_only=true \
    --benchmark_min_time=0.3 2>&1 | grep -E "^BM_.*_median" || true
}
# When, at which commit, on what.
provenance() {
  echo "# $1, $(date -u +%Y-%m-%dT%H:%MZ), commit $(git rev-parse --short HEAD)"
  echo "# machine: $(nproc) cores, $(lscpu | sed -n 's/^Model name: *//p')"
}
{
  provenance "Sylva particle benchmarks"
  echo "# BM_Step: gravity + linear/quadratic drag + one plane collider; args: particles/threads/% resting on the plane"
  echo "#   (every timed step starts from the same state); items = particle steps"
  echo "# BM_BulkStep: the same scene in BulkSystem (single precision, structure of arrays, AVX)"
  echo "# BM_GridBuild: two-pass counting-sorted grid, args: points/threads; BM_Flocking: boids/threads, ~20 neighbours"
  echo "# BM_Cloth: one 1/60 s frame, args: k (k x k particles)/threads; stretch = largest structural strain"
  medians build/bench/bench_particles
} | tee "$out-particles.txt"
if [[ -x build/bench/bench_bullet_cloth ]]; then
  {
    provenance "Sylva cloth against Bullet $(pkg-config --modversion bullet) btSoftBody"
    echo "# one 1/60 s frame (20 substeps) of a k x k, 1 kg, 1 m cloth pinned at two corners, after 3 s of fall;"
    echo "# Sylva args: k/threads; Bullet args: k/position iterations a substep (1 = Sylva's work)"
    echo "# sag: free corners below the pins at 3 s (m); stretch: largest structural strain at 3 s; peak: over the 3 s"
    medians build/bench/bench_bullet_cloth
  } | tee "$out-bullet.txt"
else
  echo "bench_bullet_cloth not built (apt-get install libbullet-dev): no Bullet comparison"
fi
