#!/bin/sh
# Runs mpc.py: Crocoddyl's MPC of the planar arm beside hrm's `mpc/solve_N` and `mpc_loop`.
#
#   python3 -m venv /tmp/croc && /tmp/croc/bin/pip install crocoddyl pin
#   PYTHON=/tmp/croc/bin/python benches/crocoddyl/run.sh [--no-loop]
#
# `cargo xtask bench --check` runs it once a round with PYTHON set to its virtual environment
# (benches/requirements.txt). Crocoddyl's solver is C++; Python only sets up each solve.
set -eu
PYTHON=${PYTHON:-python3}
HERE=$(cd "$(dirname "$0")" && pwd)
# One thread, like hrm's solve: an OpenMP team spinning on a loaded 2-core machine is slower.
export OMP_NUM_THREADS=${OMP_NUM_THREADS:-1}
exec "$PYTHON" "$HERE/mpc.py" "$@"
