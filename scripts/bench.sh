#!/usr/bin/env bash
# Runs the dynamics benchmarks (build/bench/saltus_bench) and prints each kernel next to the
# best peer figure measured on this machine kind (Pinocchio 3, RBDL 3.3, MuJoCo 2.2.2, DART 6.12;
# 100k random samples, gravity 0, on this project's 2-core machine), and the cost of the AD
# Jacobian of RNEA relative to RNEA itself (target ≤ 10×).
# Usage: scripts/bench.sh [extra Google Benchmark flags, e.g. --benchmark_repetitions=5]
set -euo pipefail
cd "$(dirname "$0")/.."
[ -x build/bench/saltus_bench ] || bash scripts/build.sh release
out=$(mktemp)
trap 'rm -f "$out"' EXIT
build/bench/saltus_bench --benchmark_filter='^BM_(RNEA|CRBA|ABA|PointJacobian|RNEA_AD_Jacobian|ABA_AD_Jacobian)/' \
  --benchmark_min_time=0.5 --benchmark_repetitions=3 \
  --benchmark_report_aggregates_only=true --benchmark_format=json "$@" > "$out"
python3 scripts/bench_table.py "$out"
