#!/bin/sh
# Builds chain.cpp and spatial.cpp against the Pinocchio of the `pin` wheel and runs them.
#
#   python3 -m venv /tmp/pin && /tmp/pin/bin/pip install pin cmeel-eigen cmeel-urdfdom-headers
#   PYTHON=/tmp/pin/bin/python benches/pinocchio/run.sh [build | run]
#
# `build` only compiles, `run` only runs the program built before, no argument does both
# (`cargo xtask bench --check` builds once, then runs it once a round, with PYTHON set to its
# virtual environment, which holds benches/requirements.txt, and the program under
# $HRM_BENCH_DIR). The wheel (a cmeel package) ships the headers and shared libraries under
# site-packages/cmeel.prefix; cmeel-eigen adds Eigen's headers there, cmeel-urdfdom-headers
# those of the URDF model that Pinocchio's URDF parser includes. Built with -O3 and no
# -march flag, like the Rust benches (no target-cpu setting). The definitions are the ones
# Pinocchio's CMake config exports to its users. spatial.cpp reads the spatial arms' URDF
# exports and modal maps, which `build` writes with hrm-benches' example spatial_urdf (cargo).
set -eu
PYTHON=${PYTHON:-python3}
HERE=$(cd "$(dirname "$0")" && pwd)
OUT=${OUT:-${HRM_BENCH_DIR:-/tmp}/hrm-pinocchio-bench}
ARMS=$OUT-spatial-arms
MODE=${1:-all}
if [ "$MODE" = build ] || [ "$MODE" = all ]; then
  PREFIX=$("$PYTHON" -c 'import sysconfig; print(sysconfig.get_paths()["purelib"])')/cmeel.prefix
  if [ ! -d "$PREFIX/include/pinocchio" ]; then
    echo "Pinocchio's headers are not under $PREFIX: pip install pin cmeel-eigen cmeel-urdfdom-headers" >&2
    exit 1
  fi
  c++ -O3 -DNDEBUG -std=c++17 -DBOOST_MPL_CFG_NO_PREPROCESSED_HEADERS \
      -DBOOST_MPL_LIMIT_LIST_SIZE=30 -DBOOST_MPL_LIMIT_VECTOR_SIZE=30 -DBOOST_FUSION_INVOKE_MAX_ARITY=12 \
      -DPINOCCHIO_ENABLE_TEMPLATE_INSTANTIATION "$HERE/chain.cpp" -o "$OUT" \
      -I"$PREFIX/include" -I"$PREFIX/include/eigen3" \
      -L"$PREFIX/lib" -Wl,-rpath,"$PREFIX/lib" -lpinocchio_default
  c++ -O3 -DNDEBUG -std=c++17 -DBOOST_MPL_CFG_NO_PREPROCESSED_HEADERS \
      -DBOOST_MPL_LIMIT_LIST_SIZE=30 -DBOOST_MPL_LIMIT_VECTOR_SIZE=30 -DBOOST_FUSION_INVOKE_MAX_ARITY=12 \
      -DPINOCCHIO_ENABLE_TEMPLATE_INSTANTIATION "$HERE/spatial.cpp" -o "$OUT-spatial" \
      -I"$PREFIX/include" -I"$PREFIX/include/eigen3" -I"$PREFIX/include/urdfdom_headers" \
      -L"$PREFIX/lib" -Wl,-rpath,"$PREFIX/lib" -lpinocchio_parsers -lpinocchio_default
  (cd "$HERE/../.." && cargo run --quiet --package hrm-benches --example spatial_urdf -- "$ARMS" > /dev/null)
fi
if [ "$MODE" = run ] || [ "$MODE" = all ]; then
  "$OUT"
  "$OUT-spatial" "$ARMS"
fi
