"""The tour of docs/python.md: the paper's arm, its modal model, inverse kinematics, dynamics in
batches, and the paper's fuzzy controller. Run: python examples/python/quickstart.py"""

import numpy as np

import hrm

# The paper's arm: ten 0.1 m, 0.1 kg uniform links; alpha0 held at pi/2 (section 5).
arm = hrm.Arm()
model = hrm.ReducedModel(arm, alpha0=np.pi / 2)
a = model.ik([0.3, 0.5])  # modal coordinates (a1, a2) of the curve ending at (0.3, 0.5), eqs 5-6
print("a =", a, " chain tip =", model.fk(a))
print("M* =\n", model.mass_matrix(a))
print("a_ddot under gravity alone:", model.forward_dynamics(a, np.zeros(2), np.zeros(2)))

# The torques that hold the arm still there: tau* = G*, and the actuators' share of it.
tau = model.joint_torques(a, np.zeros(2), np.zeros(2))
print("joint torques holding the pose (N m):", np.round(tau, 4))
assert np.allclose(tau @ model.jacobian, model.gravity(a), atol=1e-12)

# A batch: 100,000 random modal states at once, on all cores.
rng = np.random.default_rng(0)
states = rng.uniform(-0.5, 0.5, size=(100_000, 2))
accelerations = model.forward_dynamics(states, np.zeros_like(states), np.zeros_like(states))
print("batch:", accelerations.shape, "max |a_ddot| =", np.abs(accelerations).max())

# The paper's fuzzy controller: (da1, da2, a1_dot, a2_dot) -> (tau1*, tau2*).
controller = hrm.fuzzy.paper_controller()
print(controller, "at da1 = 0.3:", controller.eval([0.3, 0.0, 0.0, 0.0]))
print("rule base passes Wang's checks:", controller.check()["passed"])
