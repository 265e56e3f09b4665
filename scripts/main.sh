#!/usr/bin/env bash
# Installs what is missing, builds the saltus program (Release, build/), then runs the main job:
# `saltus run pendulum_conveyor --out out/run_pendulum_conveyor` — the paper's pendulum on a
# conveyor belt optimised with the impulsive collocation method (the tangential impulse that
# resolves the Painlevé paradox), replayed in Saltus's time-stepper and in Bullet, rendered to a
# video (640x360, 30 fps, slow motion) and charted; everything is summed up in
# out/run_pendulum_conveyor/report.md. It exits non-zero when a step failed or the solve is
# infeasible (the report says which). With arguments it runs `build/saltus ARGS...` instead, e.g.
#   bash scripts/main.sh inspect models/benchmark/hyq.urdf --base free
set -euo pipefail

root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$root"
bash scripts/setup.sh
bash scripts/build.sh release saltus

if (($# > 0)); then
  exec build/saltus "$@"
fi

echo
echo "\$ build/saltus run pendulum_conveyor --out out/run_pendulum_conveyor"
build/saltus run pendulum_conveyor --out out/run_pendulum_conveyor
echo
echo "main job done: out/run_pendulum_conveyor/report.md"
