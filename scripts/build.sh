#!/usr/bin/env bash
# Configures and builds Saltus: scripts/build.sh [release|asan] [TARGET...]
#   release (default) -> build/       Release, -O3 -march=native
#   asan              -> build-asan/  AddressSanitizer + UBSan, no benchmarks; -O1 with line tables
#                                     and assertions on (half the compile time of -O3, file:line
#                                     in sanitizer reports)
# With TARGETs (e.g. saltus) only those are built; otherwise everything.
set -euo pipefail

root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
mode="${1:-release}"
shift $(($# > 0 ? 1 : 0))
targets=()
for t in "$@"; do targets+=(--target "$t"); done
case "$mode" in
  release) dir="$root/build";      flags=(-DCMAKE_BUILD_TYPE=Release) ;;
  asan)    dir="$root/build-asan"; flags=(-DCMAKE_BUILD_TYPE=RelWithDebInfo "-DCMAKE_CXX_FLAGS_RELWITHDEBINFO=-O1 -g1"
                                          -DSALTUS_SANITIZE=ON -DSALTUS_BUILD_BENCH=OFF) ;;
  *) echo "usage: scripts/build.sh [release|asan] [TARGET...]" >&2; exit 2 ;;
esac

# ccache (scripts/packages.txt) keeps compiled objects between builds and clean clones on the same
# machine; a first build on a new machine costs the same as without it.
if command -v ccache >/dev/null 2>&1; then
  flags+=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
fi

echo "build: $mode -> ${dir#"$root"/}"
cmake -S "$root" -B "$dir" "${flags[@]}"
cmake --build "$dir" -j"$(nproc)" "${targets[@]}"
