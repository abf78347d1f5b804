"""hrm.fuzzy: the paper's controller (eqs 22-24), .fis files and the rule-base checks."""

import pathlib

import numpy as np
import pytest

import hrm
from hrm.fuzzy import System, paper_controller

PAPER_FIS = pathlib.Path(__file__).resolve().parents[2] / "fuzzy-sugeno" / "data" / "paper.fis"


def test_paper_controller_outputs():
    system = paper_controller()
    assert system.inputs == ["da1", "da2", "a1_dot", "a2_dot"] or len(system.inputs) == 4
    assert len(system.outputs) == 2
    # Zero errors and rates: no action (eq 21 with symmetric constants).
    np.testing.assert_array_equal(system.eval(np.zeros(4)), [0.0, 0.0])
    # The hand calculation of the fuzzy-sugeno crate's documentation: da1 = 0.3 gives -80.
    np.testing.assert_allclose(system.eval([0.3, 0, 0, 0]), [-80.0, 0.0], atol=1e-12)
    # Odd symmetry of the rule base: negating every input negates every output.
    x = np.random.default_rng(3).uniform(-0.5, 0.5, size=(100, 4))
    np.testing.assert_allclose(system.eval(-x), -system.eval(x), rtol=1e-12, atol=1e-12)


def test_paper_controller_pickles_by_reference():
    # A Dask worker unpickles what it is sent: the function must name an importable module.
    import pickle

    assert paper_controller.__module__ == "hrm.fuzzy"
    assert pickle.loads(pickle.dumps(paper_controller)) is paper_controller


@pytest.mark.parametrize("size", [3, 3000])
def test_batch_equals_one_by_one(size):
    system = paper_controller()
    x = np.random.default_rng(5).uniform(-1, 1, size=(size, 4))
    batch = system.eval(x)
    assert batch.shape == (size, 2)
    for i in range(0, size, max(1, size // 50)):
        np.testing.assert_array_equal(batch[i], system.eval(x[i]))


def test_fis_text_path_and_round_trip():
    preset = paper_controller()
    x = np.random.default_rng(9).uniform(-0.4, 0.4, size=(50, 4))
    for system in (System.from_fis(PAPER_FIS), System.from_fis(str(PAPER_FIS)),
                   System.from_fis(PAPER_FIS.read_text()), System.from_fis(preset.to_fis())):
        np.testing.assert_allclose(system.eval(x), preset.eval(x), rtol=1e-12, atol=1e-12)


def test_check_reports_the_three_properties():
    report = paper_controller().check()
    assert report["passed"] is True
    assert set(report) == {"passed", "completeness", "consistency", "continuity", "report"}
    assert report["consistency"]["conflicts"] == []
    assert len(report["completeness"]["outputs"]) == 2
    assert report["completeness"]["passed"] and report["continuity"]["passed"]
    assert "completeness" in report["report"].lower()
    strict = paper_controller().check(coverage=1.0)
    assert strict["completeness"]["passed"] is False and strict["passed"] is False


def test_errors(tmp_path):
    with pytest.raises(hrm.InvalidInput, match="line 3: Mamdani systems are not supported"):
        System.from_fis("[System]\nName='x'\nType='mamdani'\n")
    with pytest.raises(FileNotFoundError, match="nowhere.fis"):
        System.from_fis(tmp_path / "nowhere.fis")
    bad = tmp_path / "bad.fis"
    bad.write_text("[System]\nName='x'\nType='mamdani'\n")
    with pytest.raises(hrm.InvalidInput, match=r"bad.fis: line 3"):
        System.from_fis(bad)
    # Not a regular file (a device would never end), an empty path.
    with pytest.raises(OSError, match="not a regular file"):
        System.from_fis("/dev/zero")
    with pytest.raises(OSError, match="is a directory"):
        System.from_fis(tmp_path)
    with pytest.raises(hrm.InvalidInput, match="^path_or_text is empty"):
        System.from_fis("")
    # What a file says that is accepted but not used is a warning naming its line.
    text = PAPER_FIS.read_text().replace("AndMethod='prod'", "AndMethod='prod'\nLockRange=0", 1)
    with pytest.warns(UserWarning, match=r"^\.fis line \d+: .*LockRange"):
        System.from_fis(text)
    with pytest.raises(hrm.InvalidInput, match=r"^x has 2 entries, expected 4$"):
        paper_controller().eval([0.0, 0.0])
    with pytest.raises(hrm.InvalidInput, match="must be finite|finite"):
        paper_controller().eval([0.0, np.nan, 0.0, 0.0])
    with pytest.raises(hrm.InvalidInput, match=r"coverage must lie in \(0, 1\], got 0"):
        paper_controller().check(coverage=0.0)
    with pytest.raises(hrm.InvalidInput, match="^samples must be at least 2, got -1$"):
        paper_controller().check(samples=-1)
    # As `hrm fis check --samples`: a grid of 0 or 1 samples an input is not one.
    for samples in (0, 1, 10**6 + 1):
        with pytest.raises(hrm.InvalidInput, match=f"^samples must be at least 2 and at most 1000000, got {samples}$"):
            paper_controller().check(samples=samples)
