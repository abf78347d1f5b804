"""Per-call and batch cost of the Python bindings (docs/performance.md, "Python").

1. One state per call at n = 10: hrm.ReducedModel.forward_dynamics (the paper's three
   coordinates) beside pinocchio.aba on the same 10-link chain, and hrm.Arm.aba, in the same run.
2. A batch of 10^6 states of the 10-link reduced forward dynamics, on one core
   (RAYON_NUM_THREADS=1, in a child process) and on all cores.

Run: python benches/python/bench_reduced.py  (numpy, hrm and pin installed; `cargo xtask test`
leaves such an environment in target/python-venv). Compare the per-call figure with the Rust
cost of the same computation, `cargo xtask bench reduced_fd/10`.
"""

import os
import subprocess
import sys
import timeit

import numpy as np


def per_call(function, repeat=15, number=20_000):
    """(fastest, median) over `repeat` runs of the mean time of one call (s)."""
    runs = np.array(timeit.repeat(function, repeat=repeat, number=number)) / number
    return float(runs.min()), float(np.median(runs))


def batch_seconds(states=1_000_000, repeat=5):
    import hrm

    model = hrm.ReducedModel(hrm.Arm())
    rng = np.random.default_rng(1)
    a, a_dot, tau = rng.uniform(-0.5, 0.5, size=(3, states, 3))
    return min(timeit.repeat(lambda: model.forward_dynamics(a, a_dot, tau), repeat=repeat, number=1))


def main():
    if sys.argv[1:] == ["--batch"]:
        print(batch_seconds())
        return
    import hrm
    import pinocchio as pin

    sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "..", "crates", "hrm-py", "tests"))
    from test_pinocchio import pinocchio_chain

    arm = hrm.Arm()
    model = hrm.ReducedModel(arm)
    pin_model = pinocchio_chain(arm)
    pin_data = pin_model.createData()
    rng = np.random.default_rng(0)
    a, a_dot, tau_star = rng.uniform(-0.5, 0.5, size=(3, 3))
    q, v, tau = model.joint_angles(a), model.jacobian @ a_dot, rng.normal(size=10)

    rows = [
        ("hrm ReducedModel.forward_dynamics, one state", per_call(lambda: model.forward_dynamics(a, a_dot, tau_star))),
        ("pinocchio.aba, one state (10 links)", per_call(lambda: pin.aba(pin_model, pin_data, q, v, tau))),
        ("hrm Arm.aba, one state (10 links)", per_call(lambda: arm.aba(q, v, tau))),
    ]
    width = max(len(name) for name, _ in rows)
    print(f"{'one call':<{width}}  {'fastest':>10}  {'median':>10}")
    for name, (fastest, median) in rows:
        print(f"{name:<{width}}  {fastest * 1e6:7.3f} us  {median * 1e6:7.3f} us")
    one_core = float(subprocess.run(
        [sys.executable, __file__, "--batch"], env={**os.environ, "RAYON_NUM_THREADS": "1"},
        check=True, capture_output=True, text=True).stdout)
    print(f"10^6 states of ReducedModel.forward_dynamics (fastest of 5): {one_core:.3f} s on 1 core, "
          f"{batch_seconds():.3f} s on {os.cpu_count()} cores")


if __name__ == "__main__":
    main()
