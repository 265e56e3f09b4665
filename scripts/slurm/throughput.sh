#!/usr/bin/env bash
# Throughput of `saltus sweep --slurm` on a one-node Slurm cluster of this machine
# (local_cluster.sh) against the local runner (`saltus sweep --jobs CORES`) on the same grids:
# one solve per task and five, solves per minute, and the overhead Slurm adds per array task in
# core-seconds,
#   overhead = (wall_slurm − wall_local) × cores / tasks.
# A benchmark, not a test (it takes minutes). Needs root, slurm-wlm and munge.
#
#   scripts/slurm/throughput.sh [SALTUS] [SEEDS]    (defaults: build/saltus, 40)
set -euo pipefail

root="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
saltus="$(cd "$(dirname "${1:-$root/build/saltus}")" && pwd)/$(basename "${1:-$root/build/saltus}")"
seeds="${2:-40}"
cores="$(nproc)"
work="$(mktemp -d "${TMPDIR:-/tmp}/saltus-throughput.XXXXXX")"
cleanup() { bash "$root/scripts/slurm/local_cluster.sh" stop "$work/cluster" >/dev/null 2>&1 || true; rm -rf "$work"; }
trap cleanup EXIT

eval "$(bash "$root/scripts/slurm/local_cluster.sh" start "$work/cluster" "$cores")"
cd "$work"

now() { date +%s.%N; }
status_field() {  # DIR FIELD
  "$saltus" sweep status "$1" --json | python3 -c "import json,sys; s=json.load(sys.stdin); print(s$2)"
}

echo "| grid | solves | local --jobs $cores: wall s | solves/min | Slurm array: wall s | solves/min | overhead per task (core-s) |"
echo "| --- | ---: | ---: | ---: | ---: | ---: | ---: |"
for problem in point_mass_drop pendulum_conveyor; do
  printf 'problems: [%s]\nmethods: [impulsive]\nseeds: {from: 1, count: %s}\noptions: {restarts: 0}\n' \
    "$problem" "$seeds" >"$problem.yaml"
  start="$(now)"
  "$saltus" sweep "$problem.yaml" --out "local-$problem" --jobs "$cores" 2>/dev/null
  local_wall="$(python3 -c "print($(now) - $start)")"

  for per_task in 1 5; do
    start="$(now)"
    "$saltus" sweep "$problem.yaml" --out "slurm-$problem-$per_task" --slurm --solves-per-task "$per_task" >/dev/null 2>&1
    while [[ "$(status_field "slurm-$problem-$per_task" "['without_record']")" != 0 ]]; do sleep 0.2; done
    slurm_wall="$(python3 -c "print($(now) - $start)")"
    "$saltus" sweep collect "slurm-$problem-$per_task" 2>/dev/null
    python3 - "$problem" "$seeds" "$local_wall" "$slurm_wall" "$cores" "$per_task" <<'PY'
import sys
problem, n, local, slurm, cores, per = sys.argv[1], int(sys.argv[2]), float(sys.argv[3]), float(sys.argv[4]), int(sys.argv[5]), int(sys.argv[6])
tasks = -(-n // per)
print(f"| {problem} × impulsive × {n} seeds, {per} per task | {n} | {local:.1f} | {60 * n / local:.0f} | {slurm:.1f} | "
      f"{60 * n / slurm:.0f} | {(slurm - local) * cores / tasks:.2f} |")
PY
  done
done
