#!/usr/bin/env bash
# Builds one libFuzzer target of tests/fuzz/ and runs it: scripts/fuzz.sh TARGET SECONDS
#   build-fuzz/                  clang++ (libFuzzer + ASan + UBSan), RelWithDebInfo (-O1, line
#                                tables, assertions on), tests, benchmarks and Python off
#   build-fuzz/corpus/TARGET/    working corpus, seeded from tests/fuzz/seeds/TARGET/
#   build-fuzz/findings/TARGET/  crash-*, leak-*, timeout-*, oom-*, slow-unit-* inputs
#   build-fuzz/logs/TARGET.log   libFuzzer's output (replaced at each run)
# Ends with one summary line (target, seconds, executions, coverage, corpus, findings) and exits
# 1 when the run wrote a finding. Environment: FUZZ_JOBS (build jobs, default 2), FUZZ_ARGS
# (more libFuzzer options, e.g. FUZZ_ARGS=-seed=1).
set -euo pipefail

root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
targets=(urdf scenario problem expression trajectory solution)

usage() {
  echo "usage: scripts/fuzz.sh TARGET SECONDS"
  echo "targets: ${targets[*]}"
  echo "  urdf        dynamics::readUrdfString + ModelBuilder::build (URDF through urdfdom)"
  echo "  scenario    scene::loadScene (scenario YAML files)"
  echo "  problem     collocation::loadProblem (problem YAML files)"
  echo "  expression  scene::YamlReader::evaluate (muparser expressions of scenario parameters)"
  echo "  trajectory  scene::readTrajectoryCsv (trajectory CSV files)"
  echo "  solution    collocation::loadSolution (saved solutions: variables.csv)"
}

if (($# != 2)); then
  usage
  exit 2
fi
target="$1"
duration="$2"
if [[ " ${targets[*]} " != *" $target "* ]]; then
  echo "fuzz: unknown target '$target'" >&2
  usage >&2
  exit 2
fi
if ! [[ "$duration" =~ ^[1-9][0-9]*$ ]]; then
  echo "fuzz: SECONDS must be a positive integer, got '$duration'" >&2
  exit 2
fi

# Longest input per target: a few times the largest seed (full models and solutions stay whole).
case "$target" in
  urdf) max_len=8192 ;;
  scenario | problem) max_len=4096 ;;
  expression) max_len=256 ;;
  trajectory) max_len=16384 ;;
  solution) max_len=24576 ;;
esac

build="$root/build-fuzz"
corpus="$build/corpus/$target"
findings="$build/findings/$target"
log="$build/logs/$target.log"
seeds="$root/tests/fuzz/seeds/$target"
dict="$root/tests/fuzz/$target.dict"
mkdir -p "$corpus" "$findings" "$build/logs"

# clang and its libFuzzer runtime (a Recommends of clang-14 only, so named): installed when missing.
if ! command -v clang++ >/dev/null 2>&1 || ! compgen -G "/usr/lib/llvm-*/lib/clang/*/lib/linux/libclang_rt.fuzzer-x86_64.a" >/dev/null; then
  echo "fuzz: installing clang and libclang-rt-14-dev (libFuzzer)" >&2
  sudo_cmd=""
  [[ $(id -u) -ne 0 ]] && sudo_cmd="sudo"
  $sudo_cmd apt-get install -y --no-install-recommends clang libclang-rt-14-dev >&2
fi

# Configure once (a build folder keeps its compiler), then build only this target.
export CC=clang CXX=clang++
if [[ ! -f "$build/CMakeCache.txt" ]]; then
  flags=(-DCMAKE_CXX_COMPILER=clang++ -DCMAKE_BUILD_TYPE=RelWithDebInfo "-DCMAKE_CXX_FLAGS_RELWITHDEBINFO=-O1 -g1"
         -DSALTUS_FUZZ=ON -DSALTUS_BUILD_TESTS=OFF -DSALTUS_BUILD_BENCH=OFF -DSALTUS_BUILD_PYTHON=OFF)
  command -v ninja >/dev/null 2>&1 && flags+=(-G Ninja)
  if command -v ccache >/dev/null 2>&1; then
    flags+=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
  fi
  cmake -S "$root" -B "$build" "${flags[@]}"
fi
if command -v ccache >/dev/null 2>&1; then
  export CCACHE_BASEDIR="${CCACHE_BASEDIR:-$root}" CCACHE_NOHASHDIR="${CCACHE_NOHASHDIR:-1}"
fi
cmake --build "$build" -j"${FUZZ_JOBS:-2}" --target "fuzz_$target"
binary="$build/tests/fuzz/fuzz_$target"

# Seed the working corpus (existing files are kept: a later run goes on from the earlier corpus).
for f in "$seeds"/*; do [[ -e "$corpus/${f##*/}" ]] || cp "$f" "$corpus/"; done

options=(-max_total_time="$duration" -print_final_stats=1 -timeout=10 -rss_limit_mb=2048 -max_len="$max_len"
         -artifact_prefix="$findings/")
[[ -f "$dict" ]] && options+=(-dict="$dict")
# shellcheck disable=SC2206  # FUZZ_ARGS is split on purpose
options+=(${FUZZ_ARGS:-})

# A UBSan report stops the run like an ASan one; reports are symbolised (file:line).
export UBSAN_OPTIONS="${UBSAN_OPTIONS:-halt_on_error=1:print_stacktrace=1}"
export ASAN_OPTIONS="${ASAN_OPTIONS:-detect_leaks=1}"
for s in llvm-symbolizer /usr/lib/llvm-14/bin/llvm-symbolizer; do
  if command -v "$s" >/dev/null 2>&1; then
    export ASAN_SYMBOLIZER_PATH="${ASAN_SYMBOLIZER_PATH:-$(command -v "$s")}"
    break
  fi
done

before="$(mktemp)"
trap 'rm -f "$before"' EXIT
find "$findings" -maxdepth 1 -type f -printf '%f\n' | sort >"$before"
echo "fuzz: $target for ${duration} s (log: ${log#"$root"/})"
start=$(date +%s)
rc=0
# A deadline over libFuzzer's own: its timeout handler can deadlock when the alarm comes while the
# ASan allocator holds its lock (seen on the yaml-cpp LoadAll hang), and then it never exits.
(cd "$build" && timeout -k 10 $((duration + 120)) "$binary" "${options[@]}" "$corpus") >"$log" 2>&1 || rc=$?
elapsed=$(($(date +%s) - start))
# The targets' temporary folders /tmp/saltus_fuzz_<target>_<pid> of processes that did not exit
# normally (a crash, a timeout, -fork's children): those whose process is gone. rm does not
# follow their links into the source tree.
for d in /tmp/saltus_fuzz_"$target"_*; do
  [[ -d "$d" ]] && ! kill -0 "${d##*_}" 2>/dev/null && rm -rf "$d"
done
if ((rc == 124 || rc == 137)); then
  echo "fuzz: $target: libFuzzer had not stopped $((duration + 120)) s after its start: killed (hung in a timeout report?)" |
    tee -a "$log" >&2
fi

# The figures: libFuzzer's final stats and its last status line ("#N ... cov: C ft: F corp: ...").
stat() { sed -n "s/^stat::$1: *//p" "$log" | tail -n 1; }
execs="$(stat number_of_executed_units)"
rate="$(stat average_exec_per_sec)"
# With -fork the parent's lines are "#N: cov: ..." (the children's logs may follow them).
status="$(grep -E '^#[0-9]+: cov: [0-9]+ ft: [0-9]+' "$log" | tail -n 1 || true)"
[[ -n "$status" ]] || status="$(grep -E '^#[0-9]+.* cov: [0-9]+ ft: [0-9]+' "$log" | tail -n 1 || true)"
cov="$(sed -n 's/.* cov: \([0-9]*\).*/\1/p' <<<"$status")"
ft="$(sed -n 's/.* ft: \([0-9]*\).*/\1/p' <<<"$status")"
corp="$(sed -n 's/.* corp: \([^ ]*\).*/\1/p' <<<"$status")"
# With -fork (FUZZ_ARGS) there are no final stats: the executions are the last status line's #N.
[[ -n "$execs" ]] || execs="$(sed -n 's/^#\([0-9]*\).*/\1/p' <<<"$status")"
[[ -n "$rate" || -z "$execs" ]] || rate=$((execs / (elapsed > 0 ? elapsed : 1)))
files=$(find "$corpus" -type f | wc -l)
mapfile -t new < <(find "$findings" -maxdepth 1 -type f -printf '%f\n' | sort | comm -13 "$before" -)

if ((${#new[@]} > 0)); then
  echo "fuzz: $target: ${#new[@]} finding(s):"
  for f in "${new[@]}"; do echo "  ${findings#"$root"/}/$f"; done
  # The report's first lines, then its top frames outside libFuzzer, the sanitizers and libc.
  grep -m 6 -E '^==[0-9]+== ?ERROR|^SUMMARY|runtime error:|^terminate called|what\(\):|out-of-memory|timeout after' "$log" |
    sed 's/^/  | /' || true
  grep -E '^ +#[0-9]+ ' "$log" | grep -vE 'fuzzer::|__sanitizer|__asan|__ubsan|__lsan|libc\.so|__libc_start|in _start|in main ' |
    head -n 8 | sed -e 's/ (BuildId: [0-9a-f]*)//' -e 's/std::__cxx11::basic_string<char, std::char_traits<char>, std::allocator<char> >/std::string/g' \
                    -e 's/^ */  | /' | cut -c1-220 || true
fi
summary="fuzz-summary: target=$target seconds=$elapsed execs=${execs:-?} exec/s=${rate:-?} cov=${cov:-?} ft=${ft:-?}"
summary+=" corpus=$files files (libFuzzer corp: ${corp:-?}) findings=${#new[@]}"
echo "$summary" | tee -a "$log"

if ((${#new[@]} > 0)); then exit 1; fi
if ((rc != 0)); then
  echo "fuzz: $target: libFuzzer exited with $rc and wrote no finding; see ${log#"$root"/}" >&2
  exit "$rc"
fi
