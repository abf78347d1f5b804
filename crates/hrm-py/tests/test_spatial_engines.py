"""Spatial modal arms (hrm.SpatialArm) against Pinocchio and MuJoCo through the arm's own export:
the URDF (`to_urdf`, joints in the order of theta) loaded in Pinocchio gives J^T M J, J^T C,
J^T G, the joint torques of a modal motion and the derivatives of the reduced forward dynamics
(J^T dtau/dq J, J^T dtau/dv J through M*^-1) equal to hrm's to 1e-9 relative; the MJCF
(`to_mjcf`) loaded in MuJoCo gives the same J^T M J and J^T (C + G)."""

import numpy as np
import pytest

import hrm
from engines import require

try:
    import pinocchio as pin
except ImportError:
    pin = None
try:
    import mujoco
except ImportError:
    mujoco = None

TOL = 1e-9


def close(a, b, what):
    a, b = np.asarray(a, float), np.asarray(b, float)
    scale = max(1.0, np.abs(b).max())
    err = np.abs(a - b).max() / scale
    assert err <= TOL, f"{what}: relative difference {err:.3e}"


def arm(seed, links, harmonics):
    """A random arm: unequal links, full principal inertias, a turned base, a tilted gravity."""
    rng = np.random.default_rng(seed)
    spread = rng.uniform(0.001, 0.01, (links, 3))
    inertias = [[y + z, x + z, x + y] for x, y, z in spread]
    return hrm.SpatialArm(
        lengths=rng.uniform(0.05, 0.15, links).tolist(),
        masses=rng.uniform(0.05, 0.5, links).tolist(),
        inertias=inertias,
        gravity=[0.5, -1.0, -9.81],
        base_xyz=rng.uniform(-0.5, 0.5, 3).tolist(),
        base_rpy=rng.uniform(-1.5, 1.5, 3).tolist(),
        harmonics=harmonics,
    )


def pin_q(model, theta):
    """Pinocchio's configuration (continuous joints take cos and sin)."""
    q = []
    for joint, value in zip(list(model.joints)[1:], theta):
        q += [np.cos(value), np.sin(value)] if joint.nq == 2 else [value]
    return np.array(q)


def symmetric(upper):
    return np.triu(upper) + np.triu(upper, 1).T


def motion(arm, seed):
    rng = np.random.default_rng(100 + seed)
    m = arm.n_coords
    return rng.uniform(-0.8, 0.8, m), rng.uniform(-1.5, 1.5, m), rng.uniform(-1, 1, m)


@pytest.mark.parametrize("seed,links,harmonics", [(0, 4, 1), (1, 10, 1), (2, 10, 2), (3, 25, 2), (4, 8, 3)])
def test_reduced_dynamics_agree_with_pinocchio(seed, links, harmonics):
    require(pin is not None, "Pinocchio (pin)")
    spatial = arm(seed, links, harmonics)
    a, a_dot, tau_star = motion(spatial, seed)
    model = pin.buildModelFromXML(spatial.to_urdf())
    model.gravity.linear = np.array(spatial.gravity)
    data = model.createData()
    assert model.nv == 2 * links
    theta, jac = spatial.joints(a)
    q, v = pin_q(model, theta), jac @ a_dot
    reduced = spatial.reduced(a, a_dot, tau_star)
    mass = symmetric(pin.crba(model, data, q))
    gravity = pin.computeGeneralizedGravity(model, data, q)
    coriolis = pin.nonLinearEffects(model, data, q, v) - gravity
    close(reduced["mass_matrix"], jac.T @ mass @ jac, "J^T M J")
    close(reduced["coriolis"], jac.T @ coriolis, "J^T C")
    close(reduced["gravity"], jac.T @ gravity, "J^T G")
    qdd = jac @ reduced["a_ddot"]
    close(reduced["joint_torques"], pin.rnea(model, data, q, v, qdd), "joint torques")
    # The derivatives of the reduced forward dynamics: -M*^-1 J^T (d tau / d q, d v) J.
    derivatives = spatial.reduced_derivatives(a, a_dot, tau_star)
    pin.computeRNEADerivatives(model, data, q, v, qdd)
    inverse = np.linalg.inv(jac.T @ mass @ jac)
    close(derivatives["d_a"], -inverse @ jac.T @ data.dtau_dq @ jac, "d a_ddot / d a")
    close(derivatives["d_a_dot"], -inverse @ jac.T @ data.dtau_dv @ jac, "d a_ddot / d a_dot")
    close(derivatives["d_tau_star"], inverse, "M*^-1")


@pytest.mark.parametrize("seed,links,harmonics", [(5, 6, 1), (6, 12, 2)])
def test_reduced_dynamics_agree_with_mujoco(seed, links, harmonics):
    require(mujoco is not None, "MuJoCo (mujoco)")
    spatial = arm(seed, links, harmonics)
    a, a_dot, tau_star = motion(spatial, seed)
    mj = mujoco.MjModel.from_xml_string(spatial.to_mjcf())
    d = mujoco.MjData(mj)
    theta, jac = spatial.joints(a)
    d.qpos[:] = theta
    d.qvel[:] = jac @ a_dot
    mujoco.mj_forward(mj, d)
    full = np.zeros((mj.nv, mj.nv))
    mujoco.mj_fullM(mj, d, full)
    reduced = spatial.reduced(a, a_dot, tau_star)
    close(reduced["mass_matrix"], jac.T @ full @ jac, "J^T M J (MuJoCo)")
    close(reduced["coriolis"] + reduced["gravity"], jac.T @ d.qfrc_bias, "J^T (C + G) (MuJoCo)")


def test_exports_are_bounded():
    message = "^links: cannot export robot 'hrm_spatial_arm': 10001 links exceed the 10000 a spatial arm is written with$"
    with pytest.raises(hrm.InvalidInput, match=message):
        hrm.SpatialArm(links=10_001).to_urdf()
