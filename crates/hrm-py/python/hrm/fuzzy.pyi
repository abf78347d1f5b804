"""Type stubs of hrm.fuzzy."""

from os import PathLike
from typing import Any, Dict, List, Union

import numpy as np
import numpy.typing as npt

class System:
    """A zero- or first-order Takagi-Sugeno fuzzy system (eqs 19-21)."""

    @staticmethod
    def from_fis(path_or_text: Union[str, "PathLike[str]"]) -> "System":
        """Loads a MATLAB .fis system from a path or from the file's text."""
    def to_fis(self) -> str:
        """The system as the text of a MATLAB .fis file."""
    @property
    def name(self) -> str:
        """The system's name."""
    @property
    def inputs(self) -> List[str]:
        """The input variables' names."""
    @property
    def outputs(self) -> List[str]:
        """The output variables' names."""
    def eval(self, x: npt.ArrayLike) -> npt.NDArray[np.float64]:
        """Outputs at x: shape (n_outputs,) or (N, n_outputs)."""
    def check(
        self, coverage: float = 0.5, samples: int = 21, max_jump: float = 1.0
    ) -> Dict[str, Any]:
        """Wang's completeness, consistency and continuity checks, as a dict (samples: 2 to
        1000000 an input)."""

def paper_controller() -> System:
    """The paper's fuzzy controller (eqs 22-24)."""
