"""hrm.SpatialArm: the spatial modal arm checked against direct formulas and the planar model."""

import pickle

import numpy as np
import pytest

import hrm

A = np.array([0.8, -0.3, -0.5, 0.2])
A_DOT = np.array([0.5, -1.0, 0.2, 0.7])
TAU = np.array([0.3, -0.2, 0.1, 0.05])


def arm():
    return hrm.SpatialArm(links=10, base_xyz=(0.0, 0.0, 0.5), base_rpy=(0.0, 0.2, 0.0))


def test_joints_are_the_constant_jacobian_times_a():
    theta, jacobian = arm().joints(A)
    assert theta.shape == (20,) and jacobian.shape == (20, 4)
    np.testing.assert_allclose(theta, jacobian @ A, atol=1e-14)
    # The two planes are decoupled copies of the planar map (eq 8).
    planar = hrm.ReducedModel(hrm.Arm(links=10), alpha0=0.0).jacobian
    np.testing.assert_array_equal(jacobian[0::2, :2], planar)
    np.testing.assert_array_equal(jacobian[1::2, 2:], planar)
    assert not jacobian[0::2, 2:].any() and not jacobian[1::2, :2].any()


def test_joint_torques_project_onto_tau_star_and_realise_a_ddot():
    spatial = arm()
    out = spatial.reduced(A, A_DOT, TAU)
    _, jacobian = spatial.joints(A)
    np.testing.assert_allclose(jacobian.T @ out["joint_torques"], TAU, atol=1e-12)
    mass = out["mass_matrix"]
    np.testing.assert_allclose(mass, mass.T, atol=1e-15)
    assert np.all(np.linalg.eigvalsh(mass) > 0)
    np.testing.assert_allclose(
        mass @ out["a_ddot"] + out["coriolis"] + out["gravity"], TAU, atol=1e-12
    )
    np.testing.assert_array_equal(spatial.forward_dynamics(A, A_DOT, TAU), out["a_ddot"])


def test_in_the_plane_it_is_the_planar_reduced_model():
    spatial = hrm.SpatialArm(gravity=(0.0, -9.81, 0.0))
    planar = hrm.ReducedModel(hrm.Arm(), alpha0=0.0)
    a, a_dot = np.array([0.8, -0.3]), np.array([0.4, 0.9])
    out = spatial.reduced(np.r_[a, 0, 0], np.r_[a_dot, 0, 0], np.zeros(4))
    np.testing.assert_allclose(out["mass_matrix"][:2, :2], planar.mass_matrix(a), atol=1e-12)
    np.testing.assert_allclose(out["coriolis"][:2], planar.coriolis(a, a_dot), atol=1e-12)
    np.testing.assert_allclose(out["gravity"][:2], planar.gravity(a), atol=1e-12)
    tip, tip_chain = spatial.fk(np.r_[a, 0, 0])
    np.testing.assert_allclose(tip_chain[:2], planar.fk(a), atol=1e-14)
    assert tip_chain[2] == 0.0 and abs(tip[2]) < 1e-15


def test_ik_then_fk_lands_on_the_target():
    spatial = arm()
    target = np.array([0.5, 0.3, 0.2])
    a = spatial.ik(target)
    _, tip_chain = spatial.fk(a)
    np.testing.assert_allclose(tip_chain, target, atol=1e-12)
    again = spatial.ik(target, guess=a)
    np.testing.assert_allclose(spatial.fk(again)[1], target, atol=1e-12)


def test_fk_of_the_straight_arm_is_the_base_axis():
    spatial = arm()
    tip, tip_chain = spatial.fk(np.zeros(4))
    pitch = 0.2  # R = Ry(0.2): the x axis goes to (cos, 0, -sin)
    expected = np.array([0.0, 0.0, 0.5]) + 1.0 * np.array([np.cos(pitch), 0.0, -np.sin(pitch)])
    np.testing.assert_allclose(tip, expected, atol=1e-12)
    np.testing.assert_allclose(tip_chain, expected, atol=1e-14)


def test_a_batch_is_each_state_bit_for_bit():
    spatial = arm()
    rng = np.random.default_rng(7)
    a, a_dot, tau = (rng.normal(scale=0.5, size=(40, 4)) for _ in range(3))
    batch = spatial.reduced(a, a_dot, tau)
    fd = spatial.forward_dynamics(a, a_dot, tau)
    theta, _ = spatial.joints(a)
    tips, chains = spatial.fk(a)
    targets = chains[:5]
    solved = spatial.ik(targets)
    for i in range(40):
        one = spatial.reduced(a[i], a_dot[i], tau[i])
        for key, value in one.items():
            np.testing.assert_array_equal(batch[key][i], value)
        np.testing.assert_array_equal(fd[i], spatial.forward_dynamics(a[i], a_dot[i], tau[i]))
        np.testing.assert_array_equal(theta[i], spatial.joints(a[i])[0])
        tip, chain = spatial.fk(a[i])
        np.testing.assert_array_equal(tips[i], tip)
        np.testing.assert_array_equal(chains[i], chain)
    for i in range(5):
        np.testing.assert_array_equal(solved[i], spatial.ik(targets[i]))


def test_pickling_keeps_the_arm():
    spatial = hrm.SpatialArm(
        lengths=[0.1, 0.2, 0.15, 0.1],
        masses=[0.3, 0.2, 0.2, 0.1],
        gravity=(1.0, 0.0, -9.0),
        base_rpy=(0.1, 0.2, 0.3),
    )
    copy = pickle.loads(pickle.dumps(spatial))
    assert repr(copy) == repr(spatial)
    np.testing.assert_array_equal(copy.inertias, spatial.inertias)
    for key, value in spatial.reduced(A, A_DOT, TAU).items():
        np.testing.assert_array_equal(copy.reduced(A, A_DOT, TAU)[key], value)


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"links": 0}, "arm.links must be at least 1"),
        ({"links": -3}, "arm.links must be at least 1"),
        ({"harmonics": 17}, "harmonics must be from 1 to 16"),
        ({"links": 1}, "arm.links must be at least 2 for a spatial arm"),
        ({"lengths": [0.1] * 4, "masses": [0.1] * 5}, "arm.masses has 5 entries"),
        ({"links": 4, "inertias": [[1.0, 0.1, 0.1]] * 4}, "triangle"),
        ({"link_mass": -1.0}, r"^arm.link_mass is invalid: link 0: mass must be positive and finite, got -1"),
        ({"link_length": -0.0}, r"^arm.link_length is invalid: link 0: length must be positive and finite, got -0"),
        ({"base_xyz": (1e300, 0.0, 0.0)}, r"^arm.base.xyz is invalid: base xyz must be at most"),
        ({"gravity": (0.0, float("nan"), 0.0)}, "gravity"),
        ({"gravity": (0.0, 0.0, -1e308)}, r"arm.gravity\[2\] must be finite and at most 1000000 m/s\^2"),
        ({"base_xyz": (float("inf"), 0.0, 0.0)}, r"base_xyz\[0\] must be finite, got inf"),
    ],
)
def test_bad_parameters_are_invalid_input(kwargs, message):
    with pytest.raises(hrm.InvalidInput, match=message):
        hrm.SpatialArm(**kwargs)


def test_bad_states_are_refused():
    spatial = arm()
    with pytest.raises(hrm.InvalidInput, match="a has 3 entries, expected 4"):
        spatial.joints(np.zeros(3))
    with pytest.raises(hrm.InvalidInput, match="a_dot"):
        spatial.reduced(np.zeros((2, 4)), np.zeros(4), np.zeros((2, 4)))
    with pytest.raises(hrm.InvalidInput):
        spatial.forward_dynamics(np.array([np.nan, 0, 0, 0]), np.zeros(4), np.zeros(4))
    with pytest.raises(hrm.Unreachable):
        spatial.ik([5.0, 0.0, 0.0])
    with pytest.raises(hrm.InvalidInput, match="guess entries must be at most 10"):
        spatial.ik([0.5, 0.3, 0.2], guess=[100.0, 0, 0, 0])
    with pytest.raises(hrm.InvalidInput, match="target"):
        spatial.ik([0.5, 0.3])
