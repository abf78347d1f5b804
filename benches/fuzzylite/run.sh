#!/bin/sh
# Builds paper.cpp against fuzzylite 6 and runs it on the paper's controller.
#
#   apt-get install libfuzzylite-dev     # Debian / Ubuntu
#   benches/fuzzylite/run.sh
#
# Built with -O3 and no -march flag, like the Rust benches.
set -eu
HERE=$(cd "$(dirname "$0")" && pwd)
OUT=${OUT:-/tmp/hrm-fuzzylite-bench}
c++ -O3 -DNDEBUG -std=c++17 "$HERE/paper.cpp" -o "$OUT" -lfuzzylite
"$OUT" "$HERE/../../crates/fuzzy-sugeno/data/paper.fis"
