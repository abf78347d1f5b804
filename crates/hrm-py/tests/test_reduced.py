"""hrm.ReducedModel: the modal map (eqs 7-11), inverse kinematics (eqs 5-6) and the reduced
dynamics (eqs 13-15), checked against the full chain of hrm.Arm and an independent quadrature."""

import numpy as np
import pytest

import hrm


@pytest.fixture
def arm():
    return hrm.Arm(lengths=[0.09, 0.11, 0.1, 0.12, 0.08, 0.1, 0.1, 0.095, 0.105, 0.1],
                   masses=np.linspace(0.15, 0.05, 10))


@pytest.fixture
def rng():
    return np.random.default_rng(11)


# Gauss-Legendre nodes and weights on [-1, 1], exact for polynomials of degree 399.
NODES, WEIGHTS = np.polynomial.legendre.leggauss(200)


def curve_end(length, coords, alpha0):
    """End point of the K-harmonic backbone curve by Gauss-Legendre quadrature of eq 4:
    alpha(s) = alpha0 + sum_k a_2k-1 sin(2 pi k s / l) + a_2k (1 - cos(2 pi k s / l))."""
    x, w = NODES, WEIGHTS
    s = 0.5 * length * (x + 1)
    alpha = np.full_like(s, alpha0)
    for k in range(len(coords) // 2):
        phase = 2 * np.pi * (k + 1) * s / length
        alpha += coords[2 * k] * np.sin(phase) + coords[2 * k + 1] * (1 - np.cos(phase))
    return 0.5 * length * np.array([w @ np.cos(alpha), w @ np.sin(alpha)])


def test_coordinates_and_jacobian(arm):
    free = hrm.ReducedModel(arm)
    assert (free.n_coords, free.n_links, free.harmonics, free.alpha0) == (3, 10, 1, None)
    assert free.jacobian.shape == (10, 3)
    np.testing.assert_array_equal(free.offset, np.zeros(10))
    fixed = hrm.ReducedModel(arm, harmonics=2, alpha0=0.7)
    assert (fixed.n_coords, fixed.alpha0) == (4, 0.7)
    np.testing.assert_array_equal(fixed.offset, np.r_[0.7, np.zeros(9)])


def test_joint_angles_follow_the_curve_at_link_midpoints(arm, rng):
    # phi_i = alpha(s_i) at the arc length of link i's midpoint; theta are its differences (eq 7).
    model = hrm.ReducedModel(arm, harmonics=2)
    a = rng.normal(size=5)
    lengths = arm.lengths
    length = lengths.sum()
    s = np.cumsum(lengths) - lengths / 2
    alpha = a[4] + sum(a[2 * k] * np.sin(2 * np.pi * (k + 1) * s / length)
                       + a[2 * k + 1] * (1 - np.cos(2 * np.pi * (k + 1) * s / length)) for k in range(2))
    np.testing.assert_allclose(np.cumsum(model.joint_angles(a)), alpha, rtol=0, atol=1e-14)
    np.testing.assert_allclose(model.joint_angles(a), model.jacobian @ a, rtol=0, atol=1e-15)


def test_fk_is_the_tip_of_the_chain(arm, rng):
    model = hrm.ReducedModel(arm, alpha0=0.3)
    a = rng.normal(size=(4, 2))
    phi = np.cumsum(model.joint_angles(a), axis=1)
    tip = np.stack([(arm.lengths * np.cos(phi)).sum(1), (arm.lengths * np.sin(phi)).sum(1)], axis=1)
    np.testing.assert_allclose(model.fk(a), tip, rtol=0, atol=1e-15)


@pytest.mark.parametrize("harmonics", [1, 2, 3])
def test_ik_reaches_the_target_with_the_backbone_curve(arm, harmonics):
    alpha0 = np.pi / 2
    model = hrm.ReducedModel(arm, harmonics=harmonics, alpha0=alpha0)
    targets = np.array([[0.3, 0.5], [-0.2, 0.6], [0.1, 0.9]])
    coords = model.ik(targets)
    assert coords.shape == (3, 2 * harmonics)
    length = arm.lengths.sum()
    for target, a in zip(targets, coords):
        np.testing.assert_allclose(curve_end(length, a, alpha0), target, rtol=0, atol=1e-12)
    # The chain's tip lies within the discretisation error of the curve's end point.
    np.testing.assert_allclose(model.fk(coords), targets, rtol=0, atol=5e-3)


def test_ik_branches_and_a_free_base_angle(arm):
    free = hrm.ReducedModel(arm)
    a = free.ik([0.3, 0.5], alpha0=1.2)
    assert a.shape == (3,) and a[2] == 1.2 and a[0] >= 0
    b = free.ik([0.3, 0.5], alpha0=1.2, branch="negative")
    assert b[0] <= 0
    np.testing.assert_allclose(curve_end(1.0, b[:2], 1.2), [0.3, 0.5], atol=1e-12)
    with pytest.raises(hrm.InvalidInput, match="give ik the base angle"):
        free.ik([0.3, 0.5])
    with pytest.raises(hrm.InvalidInput, match="holds alpha0 fixed at 0.5"):
        hrm.ReducedModel(arm, alpha0=0.5).ik([0.3, 0.5], alpha0=0.5)
    with pytest.raises(hrm.InvalidInput, match='branch must be "positive" or "negative"'):
        free.ik([0.3, 0.5], alpha0=1.2, branch="up")


def test_unreachable_targets(arm):
    model = hrm.ReducedModel(arm, alpha0=0.0)
    with pytest.raises(hrm.Unreachable):
        model.ik([1.2, 0.5])
    targets = np.tile([0.3, 0.5], (1000, 1))
    targets[777] = [5.0, 0.0]
    with pytest.raises(hrm.Unreachable, match="^state 777: "):
        model.ik(targets)
    assert issubclass(hrm.Unreachable, ValueError)


@pytest.mark.parametrize("alpha0", [None, 0.8])
def test_reduced_terms_are_the_projection_of_the_chains(arm, rng, alpha0):
    # M* = J^T M J, C* = J^T C(theta, J a_dot), G* = J^T G(theta) (eq 14).
    model = hrm.ReducedModel(arm, harmonics=2, alpha0=alpha0)
    J = model.jacobian
    a, a_dot = rng.normal(size=(2, 5, model.n_coords))
    theta, theta_dot = model.joint_angles(a), a_dot @ J.T
    np.testing.assert_allclose(model.mass_matrix(a), J.T @ arm.mass_matrix(theta) @ J, rtol=1e-12)
    np.testing.assert_allclose(model.coriolis(a, a_dot), arm.coriolis(theta, theta_dot) @ J, rtol=1e-11, atol=1e-14)
    np.testing.assert_allclose(model.gravity(a), arm.gravity(theta) @ J, rtol=1e-12, atol=1e-15)


def test_forward_dynamics_and_joint_torques_agree(arm, rng):
    model = hrm.ReducedModel(arm)
    a, a_dot, tau_star = rng.normal(size=(3, 50, 3))
    a_ddot = model.forward_dynamics(a, a_dot, tau_star)
    tau = model.joint_torques(a, a_dot, a_ddot)
    assert tau.shape == (50, 10)
    # The actuators' torques project back onto tau* (J^T tau = tau*, eq 14) ...
    np.testing.assert_allclose(tau @ model.jacobian, tau_star, rtol=1e-10, atol=1e-12)
    # ... and are the chain's inverse dynamics along the constrained motion (eq 13).
    J = model.jacobian
    np.testing.assert_allclose(tau, arm.rnea(model.joint_angles(a), a_dot @ J.T, a_ddot @ J.T), rtol=1e-12, atol=1e-13)


@pytest.mark.parametrize("harmonics,alpha0", [(1, None), (1, 0.8), (2, None)])
def test_reduced_derivatives_are_those_of_the_forward_dynamics(arm, rng, harmonics, alpha0):
    # Central differences of eq 15 in a and a_dot; d a_ddot / d tau* = M*^-1.
    model = hrm.ReducedModel(arm, harmonics=harmonics, alpha0=alpha0)
    m = model.n_coords
    a, a_dot, tau_star = rng.normal(size=(3, m)) * 0.5
    d = model.reduced_derivatives(a, a_dot, tau_star)
    assert d["d_a"].shape == (m, m) and d["a_ddot"].shape == (m,)
    np.testing.assert_array_equal(d["a_ddot"], model.forward_dynamics(a, a_dot, tau_star))
    np.testing.assert_allclose(d["d_tau_star"] @ model.mass_matrix(a), np.eye(m), atol=1e-10)
    h = 1e-6
    for name, point in [("d_a", a), ("d_a_dot", a_dot)]:
        for j in range(m):
            step = np.zeros(m)
            step[j] = h
            if name == "d_a":
                up = model.forward_dynamics(a + step, a_dot, tau_star)
                down = model.forward_dynamics(a - step, a_dot, tau_star)
            else:
                up = model.forward_dynamics(a, a_dot + step, tau_star)
                down = model.forward_dynamics(a, a_dot - step, tau_star)
            column = (up - down) / (2 * h)
            scale = np.abs(d[name]).max()
            np.testing.assert_allclose(d[name][:, j], column, atol=1e-6 * scale, err_msg=name)


@pytest.mark.parametrize("size", [5, 2000])
def test_batch_equals_one_by_one(arm, rng, size):
    model = hrm.ReducedModel(arm, alpha0=1.0)
    a, a_dot, tau = rng.normal(size=(3, size, 2)) * 0.5
    outputs = {
        "joint_angles": (model.joint_angles(a), lambda i: model.joint_angles(a[i])),
        "fk": (model.fk(a), lambda i: model.fk(a[i])),
        "mass_matrix": (model.mass_matrix(a), lambda i: model.mass_matrix(a[i])),
        "coriolis": (model.coriolis(a, a_dot), lambda i: model.coriolis(a[i], a_dot[i])),
        "gravity": (model.gravity(a), lambda i: model.gravity(a[i])),
        "forward_dynamics": (model.forward_dynamics(a, a_dot, tau), lambda i: model.forward_dynamics(a[i], a_dot[i], tau[i])),
        "joint_torques": (model.joint_torques(a, a_dot, tau), lambda i: model.joint_torques(a[i], a_dot[i], tau[i])),
    }
    derivatives = model.reduced_derivatives(a, a_dot, tau)
    for key in ["a_ddot", "d_a", "d_a_dot", "d_tau_star"]:
        outputs[key] = (derivatives[key], lambda i, key=key: model.reduced_derivatives(a[i], a_dot[i], tau[i])[key])
    # Ends of the backbone curves (reachable by construction; the chain's tips need not be).
    targets = np.array([curve_end(arm.lengths.sum(), row, 1.0) for row in a])
    outputs["ik"] = (model.ik(targets), lambda i: model.ik(targets[i]))
    for name, (batch, one) in outputs.items():
        for i in range(0, size, max(1, size // 40)):
            np.testing.assert_array_equal(batch[i], one(i), err_msg=name)


def test_float32_and_strided_modal_states(arm, rng):
    model = hrm.ReducedModel(arm)
    a = rng.normal(size=(20, 6))[:, ::2]
    a32 = a.astype(np.float32)
    np.testing.assert_array_equal(model.gravity(a), model.gravity(np.ascontiguousarray(a)))
    np.testing.assert_array_equal(model.gravity(a32), model.gravity(a32.astype(np.float64)))


def test_model_errors(arm):
    with pytest.raises(hrm.InvalidInput, match="column-rank-deficient"):
        hrm.ReducedModel(hrm.Arm(links=2))
    with pytest.raises(hrm.InvalidInput, match="harmonic"):
        hrm.ReducedModel(arm, harmonics=0)
    with pytest.raises(hrm.InvalidInput, match="harmonics must be at least 1, got -2"):
        hrm.ReducedModel(arm, harmonics=-2)
    with pytest.raises(hrm.InvalidInput, match="harmonics must be a whole number of at most 64 bits"):
        hrm.ReducedModel(arm, harmonics=2**70)
    with pytest.raises(hrm.InvalidInput, match="at most 2048 harmonics"):
        hrm.ReducedModel(arm, harmonics=10**6)
    with pytest.raises(hrm.InvalidInput, match="alpha0 must be finite"):
        hrm.ReducedModel(arm, alpha0=float("inf"))
    model = hrm.ReducedModel(arm)
    with pytest.raises(hrm.InvalidInput, match=r"^a has 2 entries, expected 3$"):
        model.gravity([0.1, 0.2])
    with pytest.raises(hrm.InvalidInput, match=r"a_dot\[1\] must be finite, got NaN"):
        model.forward_dynamics(np.zeros(3), [0, np.nan, 0], np.zeros(3))
    # Finite coordinates whose joint angles would overflow: refused by name beyond the 1e6 at
    # which a run stops, whichever method meets them.
    huge = np.full(3, np.finfo(float).max)
    for method in (lambda a: model.fk(a), lambda a: model.joint_torques(a, np.zeros(3), np.zeros(3))):
        with pytest.raises(hrm.InvalidInput, match=r"^a\[0\] must be at most 1000000 in magnitude \(rad\)"):
            method(huge)
    fixed = hrm.ReducedModel(arm, alpha0=0.0)
    with pytest.raises(hrm.InvalidInput, match=r"^a\[1\] must be at most 1000000 in magnitude \(rad\), got 1e308$"):
        fixed.fk([0.0, 1e308])
