#!/usr/bin/env bash
# Installs what is missing, builds the saltus program (Release, build/), then runs the main job:
# the bundled double pendulum through `saltus inspect`, as a readable summary and as JSON at one
# state. With arguments it runs `build/saltus ARGS...` instead, e.g.
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
