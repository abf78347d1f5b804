"""Cost of a Python controller in the loop (docs/performance.md, "Python").

The paper's tracking run (paper-tracking: 5.5 s at a 1e-4 s controller period, 55,001 samples,
RK4 on the reduced dynamics) timed two ways in one process:

1. the built-in fuzzy controller (Rust, GIL released);
2. a Python callable computing the same fuzzy law with hrm.fuzzy (the same run, bit for bit).

The cost per step of the callback is (time of 2 - time of 1) / controller samples. Part of it is
the law itself (a numpy concatenate and one System.eval call), timed on its own outside the loop;
the rest is the loop's side of the callback (five numpy arrays and a ReferenceSample built, the
call, the result read back and checked).

Run: python benches/python/bench_controller.py  (hrm and numpy installed; `cargo xtask test`
leaves such an environment in target/python-venv).
"""

import timeit
import types

import numpy as np

import hrm


def main(repeat=5):
    scenario = hrm.Scenario.builtin("paper-tracking")
    system = hrm.fuzzy.paper_controller()

    def fuzzy(t, a, a_dot, ref):
        return system.eval(np.concatenate([a - ref.a, a_dot]))

    runs = {}
    for label, controller in [("built-in fuzzy (Rust)", "fuzzy"), ("Python fuzzy law", fuzzy)]:
        run = scenario.run(controller)
        assert run.failure is None, run.failure
        runs[label] = run.summary["controller_samples"], min(
            timeit.repeat(lambda: scenario.run(controller), repeat=repeat, number=1))
    (samples, base), (_, python) = runs.values()
    a, a_dot = np.array([0.3, -0.1]), np.array([0.01, 0.02])
    ref = types.SimpleNamespace(a=np.array([0.31, -0.1]), a_dot=np.zeros(2), a_ddot=np.zeros(2))
    law = min(timeit.repeat(lambda: fuzzy(0.1, a, a_dot, ref), repeat=repeat, number=20_000)) / 20_000
    callback = (python - base) / samples
    print(f"paper-tracking, {samples} controller samples, fastest of {repeat} runs")
    print(f"built-in fuzzy (Rust):       {base:.3f} s, {base / samples * 1e6:6.2f} us a step")
    print(f"Python fuzzy law:            {python:.3f} s, {python / samples * 1e6:6.2f} us a step")
    print(f"callback cost per step:      {callback * 1e6:6.2f} us (the difference)")
    print(f"  of which the law in Python: {law * 1e6:6.2f} us a call, outside the loop")
    print(f"  the loop's side of a call:  {(callback - law) * 1e6:6.2f} us")


if __name__ == "__main__":
    main()
