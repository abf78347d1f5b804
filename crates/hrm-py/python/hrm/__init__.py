"""hrm: hyper-redundant manipulators from Python.

Planar chain dynamics (``Arm``), spatial chains read from URDF (``Chain``), the modal reduction of the paper's backbone-curve method
(``ReducedModel``), spatial arms of universal joints on a modal backbone curve
(``SpatialArm``), Takagi-Sugeno fuzzy systems (``hrm.fuzzy``), closed-loop experiments
(``Scenario``, run with a built-in or a Python controller into a ``Run``) and Monte Carlo
sweeps (``Sweep``, whole or shard by shard), computed by the Rust crates of
https://github.com/hrm-toolkit/hrm. Every model method takes one state, shape ``(n,)``, or a
batch, shape ``(N, n)``, as numpy arrays (or anything ``numpy.asarray`` turns into real
numbers) and answers with the same leading dimension; batches, runs and sweeps release the GIL
and run on all cores.

Errors are ``InvalidInput`` (a ``ValueError``), ``Unreachable`` (a ``ValueError``) and
``NumericalError`` (an ``ArithmeticError``), with the messages the ``hrm`` command prints;
memory the system refuses is a ``MemoryError``.
See docs/python.md.
"""

from . import fuzzy
from ._hrm import (
    Arm,
    Chain,
    InvalidInput,
    NumericalError,
    ReducedModel,
    ReferenceSample,
    Run,
    Scenario,
    Settings,
    SpatialArm,
    Sweep,
    Unreachable,
    __version__,
    view_html,
)

__all__ = [
    "Arm",
    "Chain",
    "InvalidInput",
    "NumericalError",
    "ReducedModel",
    "ReferenceSample",
    "Run",
    "Scenario",
    "Settings",
    "SpatialArm",
    "Sweep",
    "Unreachable",
    "__version__",
    "fuzzy",
    "view_html",
]
