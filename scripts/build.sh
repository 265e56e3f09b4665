#!/usr/bin/env bash
# Configures and builds Saltus: scripts/build.sh [release|asan] [TARGET...]
#   release (default) -> build/       Release, -O3 -march=native
#   asan              -> build-asan/  AddressSanitizer + UBSan, no benchmarks; libraries -O1, test
#                                     programs and the saltus command -O0 (saltus_program in
#                                     CMakeLists.txt), line tables (file:line in sanitizer
#                                     reports) and assertions on
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

# Ninja (scripts/packages.txt) starts compiling a program's files while the libraries it links are
# still compiling, which Makefiles do not: both cores stay busy. A build directory keeps the
# generator it was configured with (CMake refuses to switch), so an old Makefile build/ stays one.
if [[ -f "$dir/CMakeCache.txt" ]]; then
  :
elif command -v ninja >/dev/null 2>&1; then
  flags+=(-G Ninja)
fi

# ccache (scripts/packages.txt) keeps compiled objects between builds and clean clones on the same
# machine; a first build on a new machine costs the same as without it. Paths under the checkout
# are hashed relative to it (base_dir) and the build directory is left out of the hash (hash_dir),
# so clones at different paths share hits; the absolute source path is only in the generated
# saltus/build_paths.hpp, included by the few files that need it.
if command -v ccache >/dev/null 2>&1; then
  flags+=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
  export CCACHE_BASEDIR="${CCACHE_BASEDIR:-$root}"
  export CCACHE_NOHASHDIR="${CCACHE_NOHASHDIR:-1}"
fi

echo "build: $mode -> ${dir#"$root"/}"
cmake -S "$root" -B "$dir" "${flags[@]}"
cmake --build "$dir" -j"$(nproc)" "${targets[@]}"
