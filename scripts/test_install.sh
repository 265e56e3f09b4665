#!/usr/bin/env bash
# Installs a Saltus build into a temporary prefix, builds examples/find_package against it with
# find_package(saltus) and runs it: the ball's first apex must be Newton's e² h = 0.25 m within 2 %,
# and its trajectory file must be written.
# Usage: scripts/test_install.sh BUILD_DIR
set -euo pipefail
build=$1
source_dir=$(cd "$(dirname "$0")/.." && pwd)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cmake --install "$build" --prefix "$work/prefix" > "$work/install.log"
test -x "$work/prefix/bin/saltus"
test -f "$work/prefix/lib/cmake/saltus/saltusConfig.cmake"
test -f "$work/prefix/share/saltus/models/scenes/ball_drop.yaml"
cmake -S "$source_dir/examples/find_package" -B "$work/example" -G Ninja -DCMAKE_BUILD_TYPE=Release \
  -DCMAKE_PREFIX_PATH="$work/prefix" > "$work/configure.log" || { cat "$work/configure.log"; exit 1; }
cmake --build "$work/example" > "$work/build.log" || { cat "$work/build.log"; exit 1; }
out=$(cd "$work" && "$work/example/ball_apex")
echo "$out"
test -s "$work/ball_drop.csv" || { echo "the example wrote no ball_drop.csv"; exit 1; }
apex=$(echo "$out" | awk '/first apex/ {print $3}')
awk -v a="$apex" 'BEGIN { exit !(a > 0.245 && a < 0.255) }' || { echo "apex $apex m is not 0.25 m within 2 %"; exit 1; }
