"""What the tests that drive an external engine (Slurm, Dask, ...) share: skip where the engine
is missing on a developer's machine, fail where `HRM_REQUIRE_ENGINES=1` (CI) says it must be
there."""

import os

import pytest


def require(available, what):
    """Skips the calling test when `available` is false, or fails it when the environment
    variable `HRM_REQUIRE_ENGINES` is `1` (as `.ci/run` sets it)."""
    if available:
        return
    if os.environ.get("HRM_REQUIRE_ENGINES") == "1":
        pytest.fail(f"{what} is required (HRM_REQUIRE_ENGINES=1) but missing")
    pytest.skip(f"{what} is missing")
