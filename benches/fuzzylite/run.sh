#!/bin/sh
# Builds paper.cpp against fuzzylite 6 and runs it on the paper's controller.
#
#   apt-get install libfuzzylite-dev     # Debian / Ubuntu
#   benches/fuzzylite/run.sh [build | run]
#
# `build` only compiles, `run` only runs the program built before, no argument does both
# (`cargo xtask bench --check` builds once, then runs it once a round, the program under
# $HRM_BENCH_DIR). Built with -O3 and no -march flag, like the Rust benches.
set -eu
HERE=$(cd "$(dirname "$0")" && pwd)
OUT=${OUT:-${HRM_BENCH_DIR:-/tmp}/hrm-fuzzylite-bench}
MODE=${1:-all}
if [ "$MODE" = build ] || [ "$MODE" = all ]; then
  c++ -O3 -DNDEBUG -std=c++17 "$HERE/paper.cpp" -o "$OUT" -lfuzzylite
fi
if [ "$MODE" = run ] || [ "$MODE" = all ]; then
  "$OUT" "$HERE/../../crates/fuzzy-sugeno/data/paper.fis"
fi
