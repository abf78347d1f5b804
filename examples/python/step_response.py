"""A closed loop written in Python: the paper's fuzzy controller moves the 10-link arm's modal
coordinates (a1, a2) from rest to a step target (alpha0 fixed at pi/2), with a zero-order hold at
1 ms and RK4 steps of 1 ms on the reduced dynamics of eq 15. The step stays within the
controller's input ranges: evaluated as given (MATLAB's semantics, the default), the paper's
controller held for 1 ms runs away from steps of 0.15 rad and more, which the built-in scenarios
avoid by sampling it every 0.1 ms. The built-in scenarios and
controllers of `hrm simulate` run the same loop in Rust; this shows the pieces from Python.
Run: python examples/python/step_response.py"""

import numpy as np

import hrm

model = hrm.ReducedModel(hrm.Arm(), alpha0=np.pi / 2)
controller = hrm.fuzzy.paper_controller()
target = np.array([0.1, 0.05])
dt, steps = 1e-3, 3000

a, a_dot = np.zeros(2), np.zeros(2)
for step in range(steps):
    # The controller sees the error as measured minus desired, and the modal rates.
    tau_star = controller.eval(np.concatenate([a - target, a_dot]))
    def f(x, v):
        return v, model.forward_dynamics(x, v, tau_star)
    k1 = f(a, a_dot)
    k2 = f(a + 0.5 * dt * k1[0], a_dot + 0.5 * dt * k1[1])
    k3 = f(a + 0.5 * dt * k2[0], a_dot + 0.5 * dt * k2[1])
    k4 = f(a + dt * k3[0], a_dot + dt * k3[1])
    a = a + dt / 6 * (k1[0] + 2 * k2[0] + 2 * k3[0] + k4[0])
    a_dot = a_dot + dt / 6 * (k1[1] + 2 * k2[1] + 2 * k3[1] + k4[1])
    if step % 500 == 499:
        print(f"t = {(step + 1) * dt:.1f} s  a = {a}  error = {a - target}")

# With no integral action the position error alone holds the arm against gravity: a small
# steady offset remains (README, "Path tracking").
assert np.all(np.isfinite(a)) and np.linalg.norm(a - target) < 0.1, a
print("tip:", model.fk(a), " target tip:", model.fk(target))
