"""MPC of the planar arm with Crocoddyl, beside hrm's `mpc/solve_N` and `mpc_loop` (issue 34).

The problem a Crocoddyl user would pose for the arm hrm controls in modal coordinates: the full
joint space of an arm of `n` revolute joints (1 m and 1 kg split into `n` equal links, centre of
mass at each link's midpoint, gravity 9.81 m/s^2 along -y, the base joint at `alpha0 = pi/2`),
60 nodes of 5 ms (semi-implicit Euler, `IntegratedActionModelEuler`), costs tracking the joint
reference `q_ref = J a_ref + theta_0` of hrm's modal reference (`J` the modal Jacobian of
`ModalMap::paper_fixed_alpha0`, `a_ref` the sinusoid of benches/benches/mpc.rs) and the
reference's inverse-dynamics torques, box limits on the joint torques, and warm-started solves of
at most 5 iterations of `SolverBoxFDDP`. The weights are hrm's (`MpcSettings::uniform`) carried
to joint space: with `s = |J|_F^2 / m` (the mean of `J^T J`'s diagonal), position `1e4 / s`,
rate `1 / s`, effort `1e-3 s` per joint, the terminal node 0.1 s of the running state weight;
each solve starts from hrm's regularisation, 1e-2.

Prints, for n = 10 and 30 (the figures `cargo xtask bench --check` reads):

- `crocoddyl/mpc/solve_<n> <ns> ns`: the median time of one warm-started solve (the previous
  plan shifted by one node, the references of the new horizon set, from a state slightly off
  the previous plan's prediction), as hrm's `mpc/solve_<n>` times;
- `crocoddyl/mpc_loop/<n>/tip_rms_m <metres> m`: the RMS tip error of the closed loop over 1 s
  (the arm simulated by Pinocchio's ABA and RK4 at 1 ms, re-planned every 5 ms from the
  measured state, the first planned torque held in between), against the reference's tip, the
  loop benches/examples/mpc_loop.rs runs for hrm.

The torque limits are 3 times the largest inverse-dynamics torque of each joint along the
reference (binding in the first transient, from rest onto the moving reference), as in hrm's
loop for each modal coordinate. At 1.2 and 2 times, the full arm's loop falls over: its
warm-started 5-iteration solves saturate in the transient and open gaps they do not close
(the reduced arm has no other modes to hold); at 3 times it tracks.

Run with ./run.sh (PYTHON must have `crocoddyl` and `pin` from PyPI).
"""

import math
import sys
import time

import crocoddyl
import numpy as np
import pinocchio as pin

HORIZON, STEP, ITERATIONS = 60, 0.005, 5
# The starting regularisation, hrm's (`MpcSettings::uniform`): from Crocoddyl's default (1e-9)
# the arm's warm-started solves keep their gaps open and stall (the loop falls over).
REGULARISATION = 1e-2
ALPHA0 = math.pi / 2
# The sinusoid of benches/benches/mpc.rs: a_i = offset + amplitude sin(2 pi f t + phase).
OFFSET, AMPLITUDE, FREQUENCY, PHASE = (
    np.array([1.0, 0.0]),
    np.array([0.3, 0.1]),
    np.array([1.0, 1.0]),
    np.array([0.0, 0.5]),
)
LOOP_SECONDS, PLANT_STEP, SUBSTEPS = 1.0, 0.001, 5
LIMIT_FACTOR = 3.0


def planar_arm(n):
    """n revolute-z joints, links of 1/n m and 1/n kg along x (benches/pinocchio/chain.cpp)."""
    length, mass = 1.0 / n, 1.0 / n
    model = pin.Model()
    model.gravity.linear = np.array([0.0, -9.81, 0.0])
    parent = 0
    for i in range(n):
        placement = pin.SE3.Identity()
        if i > 0:
            placement.translation = np.array([length, 0.0, 0.0])
        parent = model.addJoint(parent, pin.JointModelRZ(), placement, f"joint{i}")
        rotational = np.diag([1e-9, mass * length**2 / 12.0, mass * length**2 / 12.0])
        model.appendBodyToJoint(
            parent,
            pin.Inertia(mass, np.array([0.5 * length, 0.0, 0.0]), rotational),
            pin.SE3.Identity(),
        )
    return model


def modal_jacobian(n):
    """`ModalMap::paper_fixed_alpha0(n, alpha0)`: one harmonic, inclinations
    `phi_i = (sin x_i, 1 - cos x_i) . a` at the links' midpoints `x_i = 2 pi (i + 1/2) / n`,
    joint angles `theta_i = phi_i - phi_{i-1}` (the base joint adds `alpha0`)."""
    x = 2.0 * math.pi * (np.arange(n) + 0.5) / n
    phi = np.stack([np.sin(x), 1.0 - np.cos(x)], axis=1)
    theta = phi.copy()
    theta[1:] -= phi[:-1]
    return theta


def reference(t):
    w = 2.0 * math.pi * FREQUENCY
    s, c = np.sin(w * t + PHASE), np.cos(w * t + PHASE)
    return OFFSET + AMPLITUDE * s, AMPLITUDE * w * c, -AMPLITUDE * w * w * s


def tip(n, q):
    phi = np.cumsum(q)
    return np.array([np.cos(phi).sum(), np.sin(phi).sum()]) / n


class Arm:
    def __init__(self, n):
        self.n = n
        self.model = planar_arm(n)
        self.data = self.model.createData()
        self.jacobian = modal_jacobian(n)
        self.theta0 = np.zeros(n)
        self.theta0[0] = ALPHA0
        scale = (self.jacobian**2).sum() / self.jacobian.shape[1]
        self.weights = np.concatenate([np.full(n, 1e4 / scale), np.full(n, 1.0 / scale)])
        self.effort = 1e-3 * scale
        # Box limits: LIMIT_FACTOR times each joint's peak inverse-dynamics torque along the loop.
        peak = np.zeros(n)
        for t in np.arange(0.0, LOOP_SECONDS + HORIZON * STEP, STEP):
            peak = np.maximum(peak, np.abs(self.reference(t)[1]))
        self.limits = LIMIT_FACTOR * np.maximum(peak, 1e-6)
        self.state = crocoddyl.StateMultibody(self.model)
        actuation = crocoddyl.ActuationModelFull(self.state)
        running = []
        for _ in range(HORIZON):
            costs = crocoddyl.CostModelSum(self.state, n)
            costs.addCost("x", self.state_cost(self.weights), 1.0)
            effort = crocoddyl.CostModelResidual(
                self.state,
                crocoddyl.ActivationModelWeightedQuad(np.full(n, self.effort)),
                crocoddyl.ResidualModelControl(self.state, np.zeros(n)),
            )
            costs.addCost("u", effort, 1.0)
            dam = crocoddyl.DifferentialActionModelFreeFwdDynamics(self.state, actuation, costs)
            dam.u_lb, dam.u_ub = -self.limits, self.limits
            running.append(crocoddyl.IntegratedActionModelEuler(dam, STEP))
        terminal_costs = crocoddyl.CostModelSum(self.state, n)
        terminal_costs.addCost("x", self.state_cost(0.1 * self.weights), 1.0)
        terminal = crocoddyl.IntegratedActionModelEuler(
            crocoddyl.DifferentialActionModelFreeFwdDynamics(self.state, actuation, terminal_costs),
            0.0,
        )
        self.nodes = running + [terminal]
        self.problem = crocoddyl.ShootingProblem(np.zeros(2 * n), running, terminal)
        self.solver = crocoddyl.SolverBoxFDDP(self.problem)

    def state_cost(self, weights):
        return crocoddyl.CostModelResidual(
            self.state,
            crocoddyl.ActivationModelWeightedQuad(weights),
            crocoddyl.ResidualModelState(self.state, np.zeros(2 * self.n), self.n),
        )

    def reference(self, t):
        """The joint state and the inverse-dynamics torque of the reference at `t`."""
        a, a_dot, a_ddot = reference(t)
        q = self.jacobian @ a + self.theta0
        v, acc = self.jacobian @ a_dot, self.jacobian @ a_ddot
        return np.concatenate([q, v]), pin.rnea(self.model, self.data, q, v, acc).copy()

    def set_references(self, t):
        for k, node in enumerate(self.nodes):
            x_ref, u_ref = self.reference(t + k * STEP)
            node.differential.costs.costs["x"].cost.residual.reference = x_ref
            if k < HORIZON:
                node.differential.costs.costs["u"].cost.residual.reference = u_ref

    def solve(self, x, xs, us):
        self.problem.x0 = x
        xs = [x] + list(xs[1:])
        self.solver.solve(xs, us, ITERATIONS, False, REGULARISATION)
        return list(self.solver.xs), list(self.solver.us)

    def step(self, x, u):
        """RK4 of the full arm over one plant step."""
        n = self.n

        def f(y):
            qdd = pin.aba(self.model, self.data, y[:n], y[n:], u)
            return np.concatenate([y[n:], qdd])

        h = PLANT_STEP
        k1 = f(x)
        k2 = f(x + 0.5 * h * k1)
        k3 = f(x + 0.5 * h * k2)
        k4 = f(x + h * k3)
        return x + h / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4)


def shifted(values):
    return list(values[1:]) + [values[-1]]


def time_solve(arm, samples=15):
    """The median of warm-started solves, set up as benches/benches/mpc.rs does."""
    n = arm.n
    x_start, _ = arm.reference(0.0)
    x_start[n:] = 0.0
    arm.set_references(0.0)
    xs = [x_start] * (HORIZON + 1)
    us = [arm.reference(k * STEP)[1] for k in range(HORIZON)]
    for _ in range(5):
        xs, us = arm.solve(x_start, xs, us)
    # From the previous plan's prediction, 2 and -1 mrad and 10 mrad/s off in modal coordinates.
    x = xs[1].copy()
    x[:n] += arm.jacobian @ np.array([2e-3, -1e-3])
    x[n:] += arm.jacobian @ np.array([1e-2, 0.0])
    xs, us = shifted(xs), shifted(us)
    arm.set_references(STEP)
    times = []
    for _ in range(samples):
        start = time.perf_counter_ns()
        arm.solve(x, xs, us)
        times.append(time.perf_counter_ns() - start)
    return float(np.median(times)), arm.solver.iter


def closed_loop(arm):
    """The RMS tip error of the loop over LOOP_SECONDS, sampled at the plans."""
    n = arm.n
    x, _ = arm.reference(0.0)
    x[n:] = 0.0
    xs, us = [x] * (HORIZON + 1), [arm.reference(k * STEP)[1] for k in range(HORIZON)]
    errors = []
    plans = round(LOOP_SECONDS / STEP)
    for k in range(plans + 1):
        t = k * STEP
        x_ref, _ = arm.reference(t)
        errors.append(np.linalg.norm(tip(n, x[:n]) - tip(n, x_ref[:n])))
        if k == plans:
            break
        arm.set_references(t)
        xs, us = arm.solve(x, xs, us)
        u = np.clip(us[0], -arm.limits, arm.limits)
        xs, us = shifted(xs), shifted(us)
        for _ in range(SUBSTEPS):
            x = arm.step(x, u)
    errors = np.array(errors)
    return math.sqrt((errors**2).mean()), errors.max()


def main():
    loops = "--no-loop" not in sys.argv[1:]
    for n in (10, 30):
        arm = Arm(n)
        ns, iterations = time_solve(arm)
        print(f"crocoddyl/mpc/solve_{n} {ns:.0f} ns")
        print(f"  check: {iterations} iterations in the last timed solve")
        if loops:
            rms, peak = closed_loop(Arm(n))
            print(f"crocoddyl/mpc_loop/{n}/tip_rms_m {rms:.6e} m")
            print(f"  check: largest tip error {peak * 1e3:.3f} mm")


if __name__ == "__main__":
    main()
