"""Type stubs of the extension module hrm._hrm (re-exported by hrm and hrm.fuzzy)."""

from os import PathLike
from typing import Any, Callable, Dict, Iterable, List, Literal, Optional, Sequence, Tuple, Union

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
        link_length: Optional[float] = None,
        link_mass: Optional[float] = None,
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
        """Forward dynamics (ABA): theta_ddot, shape (n,) or (N, n); a batch runs SIMD across states."""
    def energy(self, theta: ArrayLike, theta_dot: ArrayLike) -> Union[float, Array]:
        """Kinetic plus potential energy (J): a float, or shape (N,) for a batch."""
    @staticmethod
    def from_urdf(
        urdf: Union[str, "PathLike[str]"], gravity: Sequence[float] = (0.0, 0.0, -9.81)
    ) -> Chain:
        """A spatial chain read from URDF: Chain.from_urdf(urdf, gravity)."""
    def to_urdf(self) -> str:
        """The arm as URDF text (joints about z, links along x; gravity along -y not in it)."""
    def to_mjcf(self) -> str:
        """The arm as one MJCF document, gravity along -y in <option>."""

class Chain:
    """A spatial serial chain with a fixed base read from URDF: tau = M(q) q_ddot + C(q, q_dot)
    q_dot + G(q), one entry per movable joint in chain order."""

    @staticmethod
    def from_urdf(
        urdf: Union[str, "PathLike[str]"], gravity: Sequence[float] = (0.0, 0.0, -9.81)
    ) -> "Chain":
        """The chain of URDF text (a string holding '<'), or of the regular file (at most
        32 MiB) a path-like object or other string names, under the world gravity vector
        (m/s^2)."""
    @property
    def n_joints(self) -> int:
        """Number of movable joints n."""
    @property
    def name(self) -> str:
        """The URDF robot name."""
    @property
    def joint_names(self) -> List[str]:
        """The movable joints' names, in chain order."""
    @property
    def link_names(self) -> List[str]:
        """The moving links' names (fixed links merged into them)."""
    @property
    def joint_kinds(self) -> List[str]:
        """"revolute", "continuous" or "prismatic" per joint."""
    @property
    def limits(self) -> Array:
        """Lower and upper joint limits, shape (n, 2) (infinite where none)."""
    @property
    def gravity_vector(self) -> Tuple[float, float, float]:
        """The gravitational acceleration in the base frame (m/s^2)."""
    def to_urdf(self) -> str:
        """The chain as URDF text."""
    def to_mjcf(self) -> str:
        """The chain as one MJCF document, gravity in <option>."""
    def mass_matrix(self, theta: ArrayLike) -> Array:
        """M(q) (CRBA), shape (n, n) or (N, n, n)."""
    def coriolis(self, theta: ArrayLike, theta_dot: ArrayLike) -> Array:
        """C(q, q_dot) q_dot, shape (n,) or (N, n)."""
    def gravity(self, theta: ArrayLike) -> Array:
        """G(q), shape (n,) or (N, n)."""
    def rnea(self, theta: ArrayLike, theta_dot: ArrayLike, theta_ddot: ArrayLike) -> Array:
        """Inverse dynamics tau, shape (n,) or (N, n)."""
    def aba(self, theta: ArrayLike, theta_dot: ArrayLike, tau: ArrayLike) -> Array:
        """Forward dynamics q_ddot (ABA; a batch SIMD across states), shape (n,) or (N, n)."""
    def rnea_derivatives(
        self, theta: ArrayLike, theta_dot: ArrayLike, theta_ddot: ArrayLike
    ) -> Tuple[Array, Array, Array]:
        """(tau, d tau / d q, d tau / d q_dot)."""
    def aba_derivatives(
        self, theta: ArrayLike, theta_dot: ArrayLike, tau: ArrayLike
    ) -> Tuple[Array, Array, Array, Array]:
        """(q_ddot, d q_ddot / d q, d q_ddot / d q_dot, M^-1)."""
    def frames(self, theta: ArrayLike) -> Tuple[Array, Array]:
        """(positions (n, 3), rotations (n, 3, 3)) of each moving link in the base frame."""
    def energy(self, theta: ArrayLike, theta_dot: ArrayLike) -> Union[float, Array]:
        """Kinetic plus potential energy (J)."""

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
        branch: Optional[Literal["positive", "negative"]] = "positive",
    ) -> Array:
        """Modal coordinates whose backbone curve ends at target, shape (m,) or (N, m)
        (branch None is the default, "positive")."""
    def mass_matrix(self, a: ArrayLike) -> Array:
        """M* = J^T M J, shape (m, m) or (N, m, m)."""
    def coriolis(self, a: ArrayLike, a_dot: ArrayLike) -> Array:
        """C* = J^T C, shape (m,) or (N, m)."""
    def gravity(self, a: ArrayLike) -> Array:
        """G* = J^T G, shape (m,) or (N, m)."""
    def forward_dynamics(self, a: ArrayLike, a_dot: ArrayLike, tau_star: ArrayLike) -> Array:
        """a_ddot = M*^-1 (tau* - C* - G*), shape (m,) or (N, m)."""
    def reduced_derivatives(
        self, a: ArrayLike, a_dot: ArrayLike, tau_star: ArrayLike
    ) -> Dict[str, Array]:
        """a_ddot and its analytic derivatives d_a, d_a_dot, d_tau_star = M*^-1 (m, m each)."""
    def joint_torques(self, a: ArrayLike, a_dot: ArrayLike, a_ddot: ArrayLike) -> Array:
        """tau = M J a_ddot + C + G, shape (n,) or (N, n)."""

class Settings:
    """A table of a scenario (scenario.arm, scenario.reference.sine); its keys are attributes
    that read and write the scenario itself."""

    def __getattr__(self, name: str) -> Any: ...
    def __setattr__(self, name: str, value: Any) -> None: ...
    def __delattr__(self, name: str) -> None: ...
    def to_dict(self) -> Dict[str, Any]:
        """The table as a dict (a copy)."""

class ReferenceSample:
    """The reference a Python controller receives at a sample (reference noise included)."""

    def __init__(self, a: ArrayLike, a_dot: ArrayLike, a_ddot: ArrayLike) -> None:
        """A reference sample of a, a_dot and a_ddot (each m numbers; copied), e.g. to test a
        controller outside a run."""
    @property
    def a(self) -> Array:
        """Desired modal coordinates (rad), shape (m,)."""
    @property
    def a_dot(self) -> Array:
        """Desired rates (rad/s), shape (m,)."""
    @property
    def a_ddot(self) -> Array:
        """Desired accelerations (rad/s^2), shape (m,)."""

ControllerFunction = Callable[[float, Array, Array, ReferenceSample], ArrayLike]
DisturbanceFunction = Callable[[float, Array, Array], Optional[ArrayLike]]

class Run:
    """The result of Scenario.run: time series (one row per recorded sample) and summary."""

    @property
    def t(self) -> Array:
        """Sample times (s), shape (K,)."""
    @property
    def a(self) -> Array:
        """Modal coordinates (rad), shape (K, m)."""
    @property
    def a_dot(self) -> Array:
        """Modal rates (rad/s), shape (K, m)."""
    @property
    def a_ref(self) -> Array:
        """The noise-free reference (rad), shape (K, m)."""
    @property
    def tau_star(self) -> Array:
        """Modal torques tau* held from each sample (N m), shape (K, m)."""
    @property
    def joint_torques(self) -> Array:
        """Joint torques tau = M J a_ddot + C + G (N m), shape (K, n)."""
    @property
    def tip(self) -> Array:
        """The discrete chain's tip (m), shape (K, 2); (K, 3) for a spatial arm."""
    @property
    def tip_ref(self) -> Array:
        """The reference tip (m), shape (K, 2); (K, 3) for a spatial arm."""
    @property
    def summary(self) -> Dict[str, Any]:
        """The summary metrics, with the keys of `hrm simulate`'s summary.json."""
    @property
    def failure(self) -> Optional[str]:
        """Why and when the run stopped early, or None."""
    @property
    def controller(self) -> str:
        """The controller's name, or "python" for a callable."""
    @property
    def coordinates(self) -> List[str]:
        """The names of the modal coordinates."""
    def view_html(self) -> str:
        """The run as a self-contained HTML page: the arm animated beside its time series.

        Raises InvalidInput for a run that stopped before its first sample or that the viewer
        cannot draw (an arm of more than 1,000 links); the run's data stands either way."""
    def _repr_html_(self) -> Optional[str]:
        """The page of view_html in an iframe (what Jupyter shows); None when view_html raises."""

def view_html(scene: str) -> str:
    """A scene as JSON text (docs/run-view.md) as a self-contained HTML page."""

class SpatialArm:
    """Universal-joint arm on a spatial modal backbone curve: theta = J a (2n x 4K)."""

    def __init__(
        self,
        links: Optional[int] = None,
        link_length: Optional[float] = None,
        link_mass: Optional[float] = None,
        gravity: Union[float, Sequence[float]] = (0.0, 0.0, -9.81),
        lengths: Optional[Sequence[float]] = None,
        masses: Optional[Sequence[float]] = None,
        inertias: Optional[Sequence[Sequence[float]]] = None,
        base_xyz: Sequence[float] = (0.0, 0.0, 0.0),
        base_rpy: Sequence[float] = (0.0, 0.0, 0.0),
        harmonics: int = 1,
    ) -> None: ...
    @property
    def n_links(self) -> int:
        """Number of links n (2n joint angles)."""
    @property
    def n_coords(self) -> int:
        """Number of modal coordinates m = 4K."""
    @property
    def harmonics(self) -> int:
        """Number of harmonics K per plane."""
    @property
    def lengths(self) -> Array:
        """Link lengths (m), shape (n,)."""
    @property
    def masses(self) -> Array:
        """Link masses (kg), shape (n,)."""
    @property
    def inertias(self) -> Array:
        """Principal moments [Ixx, Iyy, Izz] (kg m^2), shape (n, 3)."""
    @property
    def gravity(self) -> Tuple[float, float, float]:
        """Gravity vector (m/s^2)."""
    @property
    def base_xyz(self) -> Tuple[float, float, float]:
        """Base position (m)."""
    @property
    def base_rpy(self) -> Tuple[float, float, float]:
        """Base roll, pitch, yaw (rad)."""
    def joints(self, a: ArrayLike) -> Tuple[Array, Array]:
        """(theta (2n,) or (N, 2n), the constant Jacobian J (2n, m))."""
    def fk(self, a: ArrayLike) -> Tuple[Array, Array]:
        """(backbone curve's tip, chain's tip), each (3,) or (N, 3)."""
    def ik(self, target: ArrayLike, guess: Optional[ArrayLike] = None) -> Array:
        """Modal coordinates whose chain's tip is on target, shape (m,) or (N, m)."""
    def reduced(self, a: ArrayLike, a_dot: ArrayLike, tau_star: ArrayLike) -> Dict[str, Array]:
        """mass_matrix, coriolis, gravity, a_ddot and joint_torques at (a, a_dot) under tau*."""
    def forward_dynamics(self, a: ArrayLike, a_dot: ArrayLike, tau_star: ArrayLike) -> Array:
        """a_ddot = M*^-1 (tau* - C* - G*), shape (m,) or (N, m)."""
    def reduced_derivatives(
        self, a: ArrayLike, a_dot: ArrayLike, tau_star: ArrayLike
    ) -> Dict[str, Array]:
        """a_ddot and its analytic derivatives d_a, d_a_dot, d_tau_star = M*^-1 (m, m each)."""
    def to_urdf(self) -> str:
        """The arm's chain as URDF text (a universal joint as two revolute joints, the movable
        joints in the order of theta); at most 10,000 links."""
    def to_mjcf(self) -> str:
        """The arm's chain as MJCF text for MuJoCo, its gravity in <option>; at most 495 links."""

class Scenario:
    """A closed-loop experiment; every key of its TOML file is an attribute."""

    name: str
    description: str
    duration: float
    alpha0: Optional[Union[float, str]]
    """The base angle (rad), "free" when it is a coordinate, None for a spatial arm."""
    seed: Union[int, str]
    """The noise seed: an int, read back as a decimal str above 2**63 - 1 (as TOML holds it)."""
    record_period: Optional[float]
    modal: Settings
    arm: Settings
    initial: Optional[Settings]
    reference: Settings
    controller: Settings
    integrator: Settings
    noise: Settings
    limits: Settings
    obstacles: Optional[List[Dict[str, Any]]]
    task: Optional[Settings]
    deploy: Optional[Settings]

    @staticmethod
    def builtin(name: str) -> "Scenario":
        """A scenario shipped with hrm, by name."""
    @staticmethod
    def builtin_names() -> List[str]:
        """The names of the shipped scenarios."""
    @staticmethod
    def from_toml(path_or_text: Union[str, "PathLike[str]"]) -> "Scenario":
        """Reads a scenario from a TOML file or from its text."""
    def to_toml(self) -> str:
        """The scenario as TOML text."""
    def to_dict(self) -> Dict[str, Any]:
        """The whole scenario as a dict (a copy)."""
    def copy(self) -> "Scenario":
        """An independent copy."""
    @property
    def n_coords(self) -> int:
        """Number of modal coordinates m."""
    @property
    def coordinate_names(self) -> List[str]:
        """a1, ..., a2K, then alpha0 when it is free."""
    def run(
        self,
        controller: Union[None, str, ControllerFunction] = None,
        disturbance: Optional[DisturbanceFunction] = None,
    ) -> Run:
        """Runs the closed loop with the scenario's controller, a built-in one by name, or a
        Python callable f(t, a, a_dot, ref) -> tau_star; `disturbance` f(t, a, a_dot) -> tau_d
        (joint torques, shape (n,), or None) pushes the arm between controller samples."""
    def run_deploy(self) -> Dict[str, Any]:
        """Runs the scenario's [deploy] (follow-the-leader on the insertion axis, computed torque
        or joint-space MPC): {"summary": the summary.json of hrm simulate, "t": (K,), "q",
        "q_ref", "tau": (K, n + 1), insertion first, "points": (K, n + 1, 2) as links.csv}.
        A run that stops returns its data up to the stop, its summary with "error" and
        "stopped_at_s"; one that stops before its first recorded sample raises."""

class Sweep:
    """A Monte Carlo sweep over noise levels and seeds (hrm sweep), whole or by shards."""

    def __init__(
        self,
        scenario: Union[Scenario, str, "PathLike[str]"],
        noise_levels: Sequence[float],
        seeds: int,
        controllers: Optional[Sequence[str]] = None,
        base_seed: int = 1,
        rate_noise_ratio: float = 10.0,
        reference_noise_ratio: float = 0.0,
    ) -> None: ...
    @property
    def n_runs(self) -> int:
        """Noise levels x controllers x seeds."""
    @property
    def config(self) -> Dict[str, Any]:
        """The configuration as a dict: hrm_version, scenario, settings (the keywords), inputs."""
    @property
    def scenario(self) -> Scenario:
        """The scenario swept (a copy)."""
    def shard_runs(self, index: int, count: int) -> List[int]:
        """The run indices of shard index of count."""
    def run_shard(self, index: int = 1, count: int = 1) -> str:
        """Runs one shard (GIL released) and returns the shard file's JSON text; InvalidInput if
        a file the scenario references changed since the sweep was configured."""
    def run(self) -> Dict[str, Any]:
        """Runs the whole sweep and returns its summary.json as a dict."""
    @staticmethod
    def merge(shards: Iterable[Union[str, "PathLike[str]"]]) -> Dict[str, Any]:
        """Combines shard files (texts, paths or directories) into the whole sweep's summary."""
    def to_json(self) -> str:
        """The configuration as JSON."""
    @staticmethod
    def from_json(text: str) -> "Sweep":
        """A sweep from its configuration's JSON."""
