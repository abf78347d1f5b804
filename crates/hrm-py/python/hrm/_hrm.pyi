"""Type stubs of the extension module hrm._hrm (re-exported by hrm and hrm.fuzzy)."""

from typing import Literal, Optional, Sequence, Union

import numpy as np
import numpy.typing as npt

from . import fuzzy as fuzzy

__version__: str

ArrayLike = npt.ArrayLike
Array = npt.NDArray[np.float64]

class InvalidInput(ValueError):
    """An input outside the model's domain (shape, dtype, non-finite, non-positive, unknown)."""

class Unreachable(ValueError):
    """An inverse-kinematics target that the backbone curve cannot reach."""

class NumericalError(ArithmeticError):
    """A computation that failed in double precision."""

class Arm:
    """A planar serial chain of revolute joints under gravity along -y (eq 12)."""

    def __init__(
        self,
        links: Optional[int] = None,
        link_length: float = 0.1,
        link_mass: float = 0.1,
        gravity: float = 9.81,
        lengths: Optional[Sequence[float]] = None,
        masses: Optional[Sequence[float]] = None,
        inertias: Optional[Sequence[float]] = None,
    ) -> None: ...
    @property
    def n_links(self) -> int:
        """Number of links (and joints) n."""
    @property
    def gravity_acceleration(self) -> float:
        """Gravitational acceleration along -y (m/s^2)."""
    @property
    def lengths(self) -> Array:
        """Link lengths (m), shape (n,)."""
    @property
    def masses(self) -> Array:
        """Link masses (kg), shape (n,)."""
    @property
    def inertias(self) -> Array:
        """Link inertias about their centres of mass (kg m^2), shape (n,)."""
    @property
    def coms(self) -> Array:
        """Centre-of-mass distance from each link's joint (m), shape (n,)."""
    def mass_matrix(self, theta: ArrayLike) -> Array:
        """M(theta), shape (n, n) or (N, n, n)."""
    def coriolis(self, theta: ArrayLike, theta_dot: ArrayLike) -> Array:
        """The Coriolis and centrifugal torque vector C, shape (n,) or (N, n)."""
    def gravity(self, theta: ArrayLike) -> Array:
        """The gravity torques G, shape (n,) or (N, n)."""
    def rnea(self, theta: ArrayLike, theta_dot: ArrayLike, theta_ddot: ArrayLike) -> Array:
        """Inverse dynamics: tau = M theta_ddot + C + G, shape (n,) or (N, n)."""
    def aba(self, theta: ArrayLike, theta_dot: ArrayLike, tau: ArrayLike) -> Array:
        """Forward dynamics: theta_ddot, shape (n,) or (N, n)."""
    def energy(self, theta: ArrayLike, theta_dot: ArrayLike) -> Union[float, Array]:
        """Kinetic plus potential energy (J): a float, or shape (N,) for a batch."""

class ReducedModel:
    """The arm's dynamics in the modal coordinates of its backbone curve (eqs 7-18)."""

    def __init__(self, arm: Arm, harmonics: int = 1, alpha0: Optional[float] = None) -> None: ...
    @property
    def n_coords(self) -> int:
        """Number of modal coordinates m."""
    @property
    def n_links(self) -> int:
        """Number of links n."""
    @property
    def harmonics(self) -> int:
        """Number of harmonics K."""
    @property
    def alpha0(self) -> Optional[float]:
        """The fixed base angle (rad), or None when it is the last coordinate."""
    @property
    def jacobian(self) -> Array:
        """The constant modal Jacobian J, shape (n, m)."""
    @property
    def offset(self) -> Array:
        """theta_0 of theta = J a + theta_0, shape (n,)."""
    def joint_angles(self, a: ArrayLike) -> Array:
        """theta = J a + theta_0, shape (n,) or (N, n)."""
    def fk(self, a: ArrayLike) -> Array:
        """The chain's tip (m), shape (2,) or (N, 2)."""
    def ik(
        self,
        target: ArrayLike,
        alpha0: Optional[float] = None,
        branch: Literal["positive", "negative"] = "positive",
    ) -> Array:
        """Modal coordinates whose backbone curve ends at target, shape (m,) or (N, m)."""
    def mass_matrix(self, a: ArrayLike) -> Array:
        """M* = J^T M J, shape (m, m) or (N, m, m)."""
    def coriolis(self, a: ArrayLike, a_dot: ArrayLike) -> Array:
        """C* = J^T C, shape (m,) or (N, m)."""
    def gravity(self, a: ArrayLike) -> Array:
        """G* = J^T G, shape (m,) or (N, m)."""
    def forward_dynamics(self, a: ArrayLike, a_dot: ArrayLike, tau_star: ArrayLike) -> Array:
        """a_ddot = M*^-1 (tau* - C* - G*), shape (m,) or (N, m)."""
    def joint_torques(self, a: ArrayLike, a_dot: ArrayLike, a_ddot: ArrayLike) -> Array:
        """tau = M J a_ddot + C + G, shape (n,) or (N, n)."""
