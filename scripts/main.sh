#!/usr/bin/env bash
# Installs what is missing, builds the saltus program (Release, build/), then runs the main job
# (until the optimise → replay → render pipeline exists, the most complete thing that works):
# the paper's double pendulum through `saltus inspect`; the pendulum on a conveyor belt simulated
# by the time-stepper (the belt steps at 0.1 s and a tangential impulse brings the tip to the
# belt's speed) into out/pendulum_conveyor.csv; and a work–precision sweep of the ball drop with
# its chart in out/work_precision_ball_drop/. With arguments it runs `build/saltus ARGS...`
# instead, e.g.
#   bash scripts/main.sh inspect models/benchmark/hyq.urdf --base free
set -euo pipefail

root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$root"
bash scripts/setup.sh
bash scripts/build.sh release saltus

if (($# > 0)); then
  exec build/saltus "$@"
fi

run() {
  echo
  echo "\$ $*"
  "$@"
}
model=models/pendulum/double_pendulum.urdf
run build/saltus inspect "$model"
run build/saltus inspect "$model" --json --q=0,0.785 --v=0,0 --a=0,0 --tau=0,0
mkdir -p out
run build/saltus simulate pendulum_conveyor --duration 0.3 --out out/pendulum_conveyor.csv
run build/saltus bench work-precision ball_drop --out out/work_precision_ball_drop
run build/saltus optimize pendulum_conveyor --out out/optimize_pendulum_conveyor
echo
echo "main job done: out/pendulum_conveyor.csv, out/work_precision_ball_drop/work_precision.{csv,png,svg},"
echo "  out/optimize_pendulum_conveyor/{trajectory.csv,summary.json}"
