"""Cross-check against an independent implementation: Pinocchio (the `pin` package on PyPI).

The planar chain is built as a Pinocchio model of revolute-z joints, each link a body with its
mass, centre of mass on the link's x axis and inertia about z; gravity along -y. On random arms
with unequal lengths, masses and inertias, hrm's M, C + G (Pinocchio's nonlinear effects) and
forward dynamics must match Pinocchio's to 1e-10 relative, and so must the reduced forward
dynamics, rebuilt from Pinocchio's M and nonlinear effects through the modal Jacobian (eq 14).
"""

import numpy as np
import pytest

import hrm

pin = pytest.importorskip("pinocchio")

RELATIVE = 1e-10


def pinocchio_chain(arm):
    model = pin.Model()
    parent, placement = 0, pin.SE3.Identity()
    for i, (length, mass, com, inertia) in enumerate(zip(arm.lengths, arm.masses, arm.coms, arm.inertias)):
        joint = model.addJoint(parent, pin.JointModelRZ(), placement, f"joint{i}")
        # Rotational inertia at the centre of mass: only the z entry acts in the plane; the
        # others are set equal to it so that the body is physically valid.
        body = pin.Inertia(float(mass), np.array([com, 0.0, 0.0]), np.eye(3) * inertia)
        model.appendBodyToJoint(joint, body, pin.SE3.Identity())
        parent, placement = joint, pin.SE3(np.eye(3), np.array([length, 0.0, 0.0]))
    model.gravity.linear = np.array([0.0, -arm.gravity_acceleration, 0.0])
    return model


def random_arm(rng, n):
    lengths = rng.uniform(0.05, 0.3, n)
    masses = rng.uniform(0.05, 2.0, n)
    inertias = masses * lengths**2 / 12 * rng.uniform(0.2, 3.0, n)
    return hrm.Arm(lengths=lengths, masses=masses, inertias=inertias, gravity=rng.uniform(1.0, 20.0))


def assert_close(actual, expected):
    scale = max(np.linalg.norm(expected), 1e-300)
    assert np.linalg.norm(actual - expected) <= RELATIVE * scale, (actual, expected)


@pytest.mark.parametrize("n", [1, 2, 3, 7, 10, 25])
def test_mass_matrix_nonlinear_effects_and_aba_match_pinocchio(n):
    rng = np.random.default_rng(100 + n)
    for _ in range(5):
        arm = random_arm(rng, n)
        model = pinocchio_chain(arm)
        data = model.createData()
        q, v, tau = rng.uniform(-np.pi, np.pi, n), rng.normal(size=n) * 2, rng.normal(size=n)
        mass = pin.crba(model, data, q)
        mass = np.triu(mass) + np.triu(mass, 1).T  # crba fills the upper triangle
        assert_close(arm.mass_matrix(q), mass)
        nle = pin.nonLinearEffects(model, data, q, v)
        assert_close(arm.coriolis(q, v) + arm.gravity(q), nle)
        assert_close(arm.gravity(q), pin.computeGeneralizedGravity(model, data, q))
        assert_close(arm.aba(q, v, tau), pin.aba(model, data, q, v, tau))
        assert_close(arm.rnea(q, v, tau), pin.rnea(model, data, q, v, tau))


@pytest.mark.parametrize("harmonics, alpha0", [(1, None), (1, 0.9), (2, None), (3, -0.4)])
def test_reduced_forward_dynamics_matches_pinocchio_through_the_modal_jacobian(harmonics, alpha0):
    rng = np.random.default_rng(7 * harmonics)
    for _ in range(5):
        n = int(rng.integers(2 * harmonics + 2, 30))
        arm = random_arm(rng, n)
        reduced = hrm.ReducedModel(arm, harmonics=harmonics, alpha0=alpha0)
        model = pinocchio_chain(arm)
        data = model.createData()
        J = reduced.jacobian
        m = reduced.n_coords
        a, a_dot, tau_star = rng.normal(size=m) * 0.5, rng.normal(size=m), rng.normal(size=m)
        q, v = J @ a + reduced.offset, J @ a_dot
        mass = pin.crba(model, data, q)
        mass = np.triu(mass) + np.triu(mass, 1).T
        m_star = J.T @ mass @ J
        bias_star = J.T @ pin.nonLinearEffects(model, data, q, v)
        assert_close(reduced.mass_matrix(a), m_star)
        assert_close(reduced.coriolis(a, a_dot) + reduced.gravity(a), bias_star)
        assert_close(reduced.forward_dynamics(a, a_dot, tau_star), np.linalg.solve(m_star, tau_star - bias_star))
        # The analytic derivatives: -M*^-1 J^T (d tau / d q, d tau / d v) J at the solution.
        a_ddot = np.linalg.solve(m_star, tau_star - bias_star)
        pin.computeRNEADerivatives(model, data, q, v, J @ a_ddot)
        inverse = np.linalg.inv(m_star)
        derivatives = reduced.reduced_derivatives(a, a_dot, tau_star)
        assert_close(derivatives["d_a"], -inverse @ J.T @ data.dtau_dq @ J)
        assert_close(derivatives["d_a_dot"], -inverse @ J.T @ data.dtau_dv @ J)
        assert_close(derivatives["d_tau_star"], inverse)
