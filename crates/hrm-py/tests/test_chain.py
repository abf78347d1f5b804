"""hrm.Chain (URDF chains) and the URDF/MJCF export of planar arms: Pinocchio (`pin`) on the same
URDF to 1e-9 relative (mass matrix, C, G, RNEA, ABA, their derivatives, link poses) on the random
chains and the universal-joint snake of test_robot_engines.py; batches equal to one state at a
time bit for bit; the source rules of `from_urdf`; pickling and the URDF round trip."""

import pathlib
import pickle

import numpy as np
import pytest

import hrm
from engines import require
from test_robot_engines import TOL, close, pin, pin_model, pin_q, random_chain, snake, states, symmetric

GRAVITY = (0.0, 0.0, -9.81)


def chains():
    """(name, URDF text) of the chains compared with Pinocchio."""
    out = [(f"random-{n}", random_chain(seed, n)) for seed, n in enumerate([1, 3, 7, 13, 30])]
    out.append(("snake", snake()))
    return out


@pytest.mark.parametrize("name,urdf", chains(), ids=[c[0] for c in chains()])
def test_every_method_agrees_with_pinocchio(name, urdf):
    require(pin is not None, "Pinocchio (pin)")
    chain = hrm.Chain.from_urdf(urdf, gravity=GRAVITY)
    n = chain.n_joints
    model, data = pin_model(urdf, list(GRAVITY))
    assert model.nv == n
    theta, v, a, tau = states(n, 5)
    q = pin_q(model, theta)
    close(chain.mass_matrix(theta), symmetric(pin.crba(model, data, q)), "M")
    close(chain.gravity(theta), pin.computeGeneralizedGravity(model, data, q), "G")
    close(chain.coriolis(theta, v) + chain.gravity(theta), pin.nonLinearEffects(model, data, q, v), "C + G")
    close(chain.rnea(theta, v, a), pin.rnea(model, data, q, v, a), "RNEA")
    close(chain.aba(theta, v, tau), pin.aba(model, data, q, v, tau), "ABA")
    value, d_q, d_v = chain.rnea_derivatives(theta, v, a)
    pin.computeRNEADerivatives(model, data, q, v, a)
    close(value, data.tau, "RNEA (derivatives)")
    close(d_q, data.dtau_dq, "d tau / d q")
    close(d_v, data.dtau_dv, "d tau / d v")
    value, d_q, d_v, d_tau = chain.aba_derivatives(theta, v, tau)
    pin.computeABADerivatives(model, data, q, v, tau)
    close(value, data.ddq, "ABA (derivatives)")
    close(d_q, data.ddq_dq, "d qdd / d q")
    close(d_v, data.ddq_dv, "d qdd / d v")
    close(d_tau, symmetric(data.Minv), "M^-1")
    positions, rotations = chain.frames(theta)
    pin.forwardKinematics(model, data, q)
    close(positions, [data.oMi[i].translation for i in range(1, model.njoints)], "positions")
    close(rotations, [data.oMi[i].rotation for i in range(1, model.njoints)], "rotations")
    # Energy: kinetic 1/2 v^T M v, potential -sum m_i g . c_i over the moving links' centres of mass.
    kinetic = 0.5 * v @ chain.mass_matrix(theta) @ v
    potential = -sum(
        model.inertias[i].mass * np.dot(GRAVITY, data.oMi[i].act(model.inertias[i].lever))
        for i in range(1, model.njoints)
    )
    assert chain.energy(theta, v) == pytest.approx(kinetic + potential, rel=TOL, abs=TOL)


def test_batches_give_each_state_the_bits_it_gets_alone():
    chain = hrm.Chain.from_urdf(snake())
    n = chain.n_joints
    rng = np.random.default_rng(3)
    # 600 states: past the parallel threshold (512), and not a multiple of the SIMD width.
    theta, v, a = (rng.uniform(-1, 1, (601, n)) for _ in range(3))
    batch = chain.aba(theta, v, a)
    assert batch.shape == (601, n)
    for k in (0, 1, 7, 512, 600):
        assert np.array_equal(batch[k], chain.aba(theta[k], v[k], a[k]))
    few = slice(0, 9)
    for method, args in [
        ("mass_matrix", (theta[few],)),
        ("gravity", (theta[few],)),
        ("coriolis", (theta[few], v[few])),
        ("rnea", (theta[few], v[few], a[few])),
        ("energy", (theta[few], v[few])),
    ]:
        out = getattr(chain, method)(*args)
        for k in range(9):
            assert np.array_equal(out[k], getattr(chain, method)(*(x[k] for x in args)))
    for method in ("rnea_derivatives", "aba_derivatives", "frames"):
        args = (theta[few],) if method == "frames" else (theta[few], v[few], a[few])
        parts = getattr(chain, method)(*args)
        for k in range(9):
            alone = getattr(chain, method)(*(x[k] for x in args))
            assert len(parts) == len(alone)
            for part, one in zip(parts, alone):
                assert part.shape[1:] == one.shape
                assert np.array_equal(part[k], one)


def test_shapes_and_properties():
    chain = hrm.Chain.from_urdf(random_chain(2, 3))
    assert isinstance(chain, hrm.Chain)
    assert chain.n_joints == 3
    assert chain.name == "random"
    assert chain.joint_names == ["j1", "j2", "j3"]
    assert chain.link_names == ["l1", "l2", "l3"]
    assert set(chain.joint_kinds) <= {"revolute", "prismatic"}
    assert chain.gravity_vector == GRAVITY
    np.testing.assert_array_equal(chain.limits, [[-1.0, 1.0]] * 3)
    theta = np.zeros(3)
    assert chain.mass_matrix(theta).shape == (3, 3)
    tau, d_q, d_v = chain.rnea_derivatives(theta, theta, theta)
    assert tau.shape == (3,) and d_q.shape == d_v.shape == (3, 3)
    positions, rotations = chain.frames(np.zeros((4, 3)))
    assert positions.shape == (4, 3, 3) and rotations.shape == (4, 3, 3, 3)
    assert isinstance(chain.energy(theta, theta), float)
    assert "joints=3" in repr(chain)


def test_from_urdf_reads_paths_and_text(tmp_path):
    text = random_chain(4, 2)
    path = tmp_path / "arm.urdf"
    path.write_text(text)
    want = hrm.Chain.from_urdf(text).mass_matrix([0.1, 0.2])
    # A string holding no '<' names a file, whatever its extension.
    other = tmp_path / "ROBOT.XML"
    other.write_text(text)
    for source in (str(path), path, str(other)):
        assert np.array_equal(hrm.Chain.from_urdf(source).mass_matrix([0.1, 0.2]), want)
    with pytest.raises(hrm.InvalidInput, match=r"urdf file .*arm\.urdf : "):
        hrm.Chain.from_urdf(str(path) + " ")
    assert isinstance(hrm.Arm.from_urdf(path), hrm.Chain)
    with pytest.raises(hrm.InvalidInput, match="urdf file .*missing.urdf"):
        hrm.Chain.from_urdf(str(tmp_path / "missing.urdf"))
    with pytest.raises(hrm.InvalidInput, match="directory"):
        (tmp_path / "dir.urdf").mkdir()
        hrm.Chain.from_urdf(tmp_path / "dir.urdf")
    big = tmp_path / "big.urdf"
    with big.open("wb") as f:
        f.truncate((32 << 20) + 1)
    with pytest.raises(hrm.InvalidInput, match="more than"):
        hrm.Chain.from_urdf(big)
    with pytest.raises(hrm.InvalidInput, match="urdf"):
        hrm.Chain.from_urdf("<robot")
    with pytest.raises(hrm.InvalidInput, match="no movable joint"):
        hrm.Chain.from_urdf('<robot name="r"><link name="a"/></robot>')
    for wrong in [42, None]:
        with pytest.raises(TypeError, match="urdf must be URDF text or a path to a URDF file, got a"):
            hrm.Chain.from_urdf(wrong)
    with pytest.raises(hrm.InvalidInput, match=r"^gravity\[1\] must be finite, got NaN$"):
        hrm.Chain.from_urdf(text, gravity=(0.0, float("nan"), 0.0))


def test_bad_states_are_refused():
    chain = hrm.Chain.from_urdf(random_chain(1, 2))
    with pytest.raises(hrm.InvalidInput, match="theta has 3 entries, expected 2"):
        chain.mass_matrix([0.0, 0.0, 0.0])
    with pytest.raises(hrm.InvalidInput, match="theta_dot"):
        chain.rnea([0.0, 0.0], [[0.0, 0.0]], [0.0, 0.0])
    with pytest.raises(hrm.InvalidInput, match="finite"):
        chain.aba([np.nan, 0.0], [0.0, 0.0], [0.0, 0.0])
    with pytest.raises(hrm.InvalidInput, match="state 1"):
        chain.aba_derivatives([[0.0, 0.0], [np.inf, 0.0]], np.zeros((2, 2)), np.zeros((2, 2)))
    # A gravity beyond the bound of a URDF's numbers (1e9), as hrm eval refuses it.
    with pytest.raises(hrm.InvalidInput, match=r"^gravity: must be three finite numbers .* got \[0, 0, 1.7e308\]$"):
        hrm.Chain.from_urdf(random_chain(1, 2), gravity=(0.0, 0.0, 1.7e308))


def test_pickle_and_urdf_round_trip():
    chain = hrm.Chain.from_urdf(random_chain(6, 5), gravity=(0.0, -9.81, 0.0))
    again = pickle.loads(pickle.dumps(chain))
    assert again.gravity_vector == chain.gravity_vector
    assert again.to_urdf() == chain.to_urdf()
    theta, v, tau = states(5, 1)[:3]
    assert np.array_equal(again.aba(theta, v, tau), chain.aba(theta, v, tau))
    assert "<mujoco" in chain.to_mjcf() and 'gravity="0.0 -9.81 0.0"' in chain.to_mjcf()


def test_an_arm_mujoco_would_refuse_raises_naming_the_link():
    """MuJoCo refuses a moving body's mass or principal moment below mjMINVAL (1e-15): to_mjcf
    raises, naming the link, instead of writing a file MuJoCo does not load."""
    with pytest.raises(hrm.InvalidInput, match=r"^cannot export link 'link_1' to MJCF: MuJoCo needs a mass "
                                                r"and principal moments of inertia of at least 1e-15"):
        hrm.Arm(inertias=[1e-20, 1e-20]).to_mjcf()


def test_a_planar_arm_exported_as_urdf_has_the_planar_dynamics():
    arm = hrm.Arm(lengths=[0.1, 0.12, 0.08, 0.1], masses=[0.1, 0.2, 0.15, 0.05])
    chain = hrm.Chain.from_urdf(arm.to_urdf(), gravity=(0.0, -arm.gravity_acceleration, 0.0))
    assert "<mujoco" in arm.to_mjcf()
    theta, v, tau = np.array([0.3, -0.4, 0.5, 0.2]), np.array([0.5, 1.0, -0.3, 0.2]), np.full(4, 0.01)
    np.testing.assert_allclose(chain.mass_matrix(theta), arm.mass_matrix(theta), rtol=1e-12, atol=1e-15)
    np.testing.assert_allclose(chain.gravity(theta), arm.gravity(theta), rtol=1e-12, atol=1e-15)
    np.testing.assert_allclose(chain.coriolis(theta, v), arm.coriolis(theta, v), rtol=1e-12, atol=1e-15)
    np.testing.assert_allclose(chain.aba(theta, v, tau), arm.aba(theta, v, tau), rtol=1e-10)
    if pin is not None:
        model, data = pin_model(arm.to_urdf(), [0.0, -arm.gravity_acceleration, 0.0])
        q = pin_q(model, theta)
        close(arm.mass_matrix(theta), symmetric(pin.crba(model, data, q)), "planar M")
