"""hrm.Arm: shapes, dtypes, layouts, batches, errors and physics of the chain (eq 12)."""

import numpy as np
import pytest

import hrm

N_LINKS = 10


@pytest.fixture
def arm():
    return hrm.Arm(lengths=np.linspace(0.08, 0.12, 5), masses=[0.1, 0.2, 0.15, 0.05, 0.1])


@pytest.fixture
def rng():
    return np.random.default_rng(7)


def test_defaults_are_the_papers_arm():
    arm = hrm.Arm()
    assert arm.n_links == N_LINKS
    np.testing.assert_array_equal(arm.lengths, np.full(N_LINKS, 0.1))
    np.testing.assert_array_equal(arm.masses, np.full(N_LINKS, 0.1))
    np.testing.assert_allclose(arm.inertias, 0.1 * 0.01 / 12, rtol=1e-15)
    np.testing.assert_allclose(arm.coms, 0.05, rtol=1e-15)
    assert arm.gravity_acceleration == 9.81
    assert hrm.Arm(lengths=[0.1, 0.2]).n_links == 2


def test_one_link_is_a_pendulum():
    # A uniform beam of length L and mass m about its end: M = m L^2 / 3, G = m g L/2 cos(theta).
    arm = hrm.Arm(links=1, link_length=0.3, link_mass=2.0, gravity=9.0)
    theta, omega = np.array([0.4]), np.array([1.7])
    assert arm.mass_matrix(theta)[0, 0] == pytest.approx(2.0 * 0.09 / 3, rel=1e-14)
    assert arm.gravity(theta)[0] == pytest.approx(2.0 * 9.0 * 0.15 * np.cos(0.4), rel=1e-14)
    assert arm.coriolis(theta, omega)[0] == pytest.approx(0.0, abs=1e-15)
    energy = 0.5 * (2.0 * 0.09 / 3) * 1.7**2 + 2.0 * 9.0 * 0.15 * np.sin(0.4)
    assert arm.energy(theta, omega) == pytest.approx(energy, rel=1e-14)


def test_shapes_of_one_state_and_of_a_batch(arm, rng):
    n = arm.n_links
    q, v, w = rng.normal(size=(3, n))
    assert arm.mass_matrix(q).shape == (n, n)
    for out in (arm.coriolis(q, v), arm.gravity(q), arm.rnea(q, v, w), arm.aba(q, v, w)):
        assert out.shape == (n,) and out.dtype == np.float64
    assert isinstance(arm.energy(q, v), float)
    Q, V, W = rng.normal(size=(3, 6, n))
    assert arm.mass_matrix(Q).shape == (6, n, n)
    for out in (arm.coriolis(Q, V), arm.gravity(Q), arm.rnea(Q, V, W), arm.aba(Q, V, W)):
        assert out.shape == (6, n)
    assert arm.energy(Q, V).shape == (6,)
    assert arm.gravity(np.zeros((0, n))).shape == (0, n)


@pytest.mark.parametrize("size", [7, 1500])  # sequential, and spread over rayon's threads
def test_batch_equals_one_by_one(arm, rng, size):
    n = arm.n_links
    Q, V, T = rng.normal(size=(3, size, n))
    batch = {
        "M": arm.mass_matrix(Q),
        "C": arm.coriolis(Q, V),
        "G": arm.gravity(Q),
        "tau": arm.rnea(Q, V, T),
        "qdd": arm.aba(Q, V, T),
        "E": arm.energy(Q, V),
    }
    for i in range(0, size, max(1, size // 50)):
        q, v, t = Q[i], V[i], T[i]
        np.testing.assert_array_equal(batch["M"][i], arm.mass_matrix(q))
        np.testing.assert_array_equal(batch["C"][i], arm.coriolis(q, v))
        np.testing.assert_array_equal(batch["G"][i], arm.gravity(q))
        np.testing.assert_array_equal(batch["tau"][i], arm.rnea(q, v, t))
        np.testing.assert_array_equal(batch["qdd"][i], arm.aba(q, v, t))
        assert batch["E"][i] == arm.energy(q, v)


def test_one_array_may_be_passed_as_several_arguments(arm, rng):
    q = rng.normal(size=(3, arm.n_links))
    np.testing.assert_array_equal(arm.coriolis(q, q), arm.coriolis(q, q.copy()))


def test_inverse_and_forward_dynamics_invert_each_other(arm, rng):
    Q, V, T = rng.normal(size=(3, 40, arm.n_links))
    np.testing.assert_allclose(arm.rnea(Q, V, arm.aba(Q, V, T)), T, rtol=1e-10, atol=1e-12)
    # rnea = M qdd + C + G (eq 12).
    qdd = arm.aba(Q, V, T)
    rebuilt = np.einsum("nij,nj->ni", arm.mass_matrix(Q), qdd) + arm.coriolis(Q, V) + arm.gravity(Q)
    np.testing.assert_allclose(rebuilt, T, rtol=1e-10, atol=1e-12)


def test_energy_changes_at_the_rate_of_the_applied_power(arm, rng):
    # dE/dt = tau . theta_dot for any motion; check by a central difference along the motion.
    q, v, tau = rng.normal(size=(3, arm.n_links))
    qdd = arm.aba(q, v, tau)
    h = 1e-6
    e_plus = arm.energy(q + h * v + 0.5 * h * h * qdd, v + h * qdd)
    e_minus = arm.energy(q - h * v + 0.5 * h * h * qdd, v - h * qdd)
    assert (e_plus - e_minus) / (2 * h) == pytest.approx(tau @ v, rel=1e-6, abs=1e-9)


def test_float32_integer_and_list_inputs_are_converted(arm, rng):
    q32 = rng.normal(size=arm.n_links).astype(np.float32)
    np.testing.assert_array_equal(arm.gravity(q32), arm.gravity(q32.astype(np.float64)))
    np.testing.assert_array_equal(arm.gravity([0, 1, 0, 1, 0]), arm.gravity(np.array([0.0, 1, 0, 1, 0])))
    np.testing.assert_array_equal(
        arm.gravity(np.array([0, 1, 0, 1, 0], dtype=np.int16)), arm.gravity([0.0, 1.0, 0.0, 1.0, 0.0])
    )
    big_endian = np.arange(5, dtype=">f8") / 7
    np.testing.assert_array_equal(arm.gravity(big_endian), arm.gravity(np.arange(5) / 7))


@pytest.mark.parametrize(
    "bad, dtype",
    [(np.zeros(5, dtype=np.complex128), "complex128"), (np.array(["a"] * 5), "<U1"), (np.array([None] * 5), "object")],
)
def test_other_dtypes_are_refused_by_name(arm, bad, dtype):
    with pytest.raises(hrm.InvalidInput, match=f"theta must hold real numbers.*got dtype {dtype}"):
        arm.gravity(bad)


def test_non_contiguous_and_fortran_inputs(arm, rng):
    n = arm.n_links
    wide = rng.normal(size=(30, 2 * n))
    strided = wide[::3, ::2]
    assert not strided.flags.c_contiguous
    expected = arm.mass_matrix(np.ascontiguousarray(strided))
    np.testing.assert_array_equal(arm.mass_matrix(strided), expected)
    fortran = np.asfortranarray(strided)
    assert fortran.flags.f_contiguous and not fortran.flags.c_contiguous
    np.testing.assert_array_equal(arm.mass_matrix(fortran), expected)
    np.testing.assert_array_equal(arm.gravity(wide[0, ::2]), arm.gravity(wide[0, ::2].copy()))
    reversed_rows = np.ascontiguousarray(strided)[::-1]
    np.testing.assert_array_equal(arm.mass_matrix(reversed_rows), expected[::-1])


def test_shape_errors_name_the_input(arm):
    with pytest.raises(hrm.InvalidInput, match=r"^theta has 4 entries, expected 5$"):
        arm.gravity(np.zeros(4))
    with pytest.raises(hrm.InvalidInput, match=r"^theta_dot has shape \(3, 6\), expected \(N, 5\)$"):
        arm.coriolis(np.zeros((3, 5)), np.zeros((3, 6)))
    with pytest.raises(hrm.InvalidInput, match=r"theta must be one state of shape \(5,\) or a batch"):
        arm.gravity(np.zeros((2, 2, 5)))
    with pytest.raises(hrm.InvalidInput, match=r"theta has shape \(3, 5\) but theta_dot has shape \(5,\)"):
        arm.coriolis(np.zeros((3, 5)), np.zeros(5))
    with pytest.raises(hrm.InvalidInput, match=r"theta has shape \(3, 5\) but tau has shape \(4, 5\)"):
        arm.aba(np.zeros((3, 5)), np.zeros((3, 5)), np.zeros((4, 5)))


def test_non_finite_inputs_and_results(arm):
    q = np.zeros(5)
    q[3] = np.nan
    with pytest.raises(hrm.InvalidInput, match=r"^q\[3\] must be finite, got NaN$"):
        arm.gravity(q)
    batch = np.zeros((2000, 5))
    batch[1234, 2] = np.inf
    batch[1900, 0] = np.nan
    with pytest.raises(hrm.InvalidInput, match=r"^state 1234: q\[2\] must be finite, got inf$"):
        arm.gravity(batch)
    # Rates beyond the scale a run resolves (1e200 overflowed the Coriolis terms).
    with pytest.raises(hrm.InvalidInput, match=r"^theta_dot\[0\] must be at most 1000000 in magnitude"):
        arm.coriolis(np.zeros(5), np.full(5, 1e200))


def test_arm_parameters_are_checked_as_the_cli_does():
    with pytest.raises(hrm.InvalidInput, match=r"^arm\.masses\[1\] is invalid: link 1: mass must be positive and finite, got -1$"):
        hrm.Arm(masses=[0.1, -1])
    with pytest.raises(hrm.InvalidInput, match=r"^arm.lengths has 3 entries but the arm has 4 links$"):
        hrm.Arm(links=4, lengths=[0.1, 0.1, 0.1])
    with pytest.raises(hrm.InvalidInput, match=r"^arm.links must be at least 1"):
        hrm.Arm(links=0)
    with pytest.raises(hrm.InvalidInput, match=r"^arm.links must be at least 1, got -3$"):
        hrm.Arm(links=-3)
    with pytest.raises(hrm.InvalidInput, match=r"^arm.lengths is empty: an arm has at least 1 link$"):
        hrm.Arm(lengths=[])
    with pytest.raises(hrm.InvalidInput, match=r"^arm.links must be at most 1000000, got 1000000000$"):
        hrm.Arm(links=10**9)
    with pytest.raises(hrm.InvalidInput, match=r"^arm.links must be a whole number of at most 64 bits, got 10{30}$"):
        hrm.Arm(links=10**30)
    with pytest.raises(hrm.InvalidInput, match="gravity must be finite"):
        hrm.Arm(gravity=float("nan"))


def test_too_large_a_result_is_refused_before_allocating():
    arm = hrm.Arm(links=4096)
    theta = np.broadcast_to(np.zeros(4096), (20, 4096))  # 20 x 4096 x 4096 > 2^28 values
    with pytest.raises(hrm.InvalidInput, match="more than the limit of 268435456: split the batch"):
        arm.mass_matrix(theta)


def test_a_numerically_singular_mass_matrix_is_a_numerical_error():
    # A nearly massless link followed by a nearly point-like one: straight out, M is singular to
    # double precision (manip-dyn's own test of this refusal uses the same kind of arm).
    arm = hrm.Arm(lengths=[0.5, 0.5], masses=[1e-30, 1e-10], inertias=[1e-33, 1e-43])
    with pytest.raises(hrm.NumericalError, match="not numerically positive definite"):
        arm.aba(np.zeros(2), np.zeros(2), np.zeros(2))
