"""Takagi-Sugeno fuzzy systems (the paper's eqs 19-24): MATLAB .fis files, evaluation on
numpy arrays, and Wang's completeness, consistency and continuity checks."""

from ._hrm import fuzzy as _fuzzy

System = _fuzzy.System
paper_controller = _fuzzy.paper_controller

__all__ = ["System", "paper_controller"]
