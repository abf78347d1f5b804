"""Sweeps from Python: plan, shards scheduled by concurrent.futures, merge equal to the
unsharded sweep and to `hrm sweep`'s summary.json, and the merge's refusals."""

import concurrent.futures
import json
import pickle
import subprocess

import pytest

import hrm
from test_scenario import hrm_binary


def small_sweep():
    scenario = hrm.Scenario.builtin("paper-responses-step")
    scenario.duration = 0.1
    return hrm.Sweep(scenario, noise_levels=[0.0, 0.01], seeds=3, controllers=["pd", "fuzzy"], base_seed=5)


def test_plan():
    sweep = small_sweep()
    assert sweep.n_runs == 2 * 2 * 3
    shards = [sweep.shard_runs(k, 5) for k in range(1, 6)]
    assert sorted(i for shard in shards for i in shard) == list(range(sweep.n_runs))
    assert shards[1] == [1, 6, 11]
    with pytest.raises(hrm.InvalidInput, match=r"^index must be from 1 to count \(5\), got 6$"):
        sweep.shard_runs(6, 5)
    with pytest.raises(hrm.InvalidInput, match=r"^index must be from 1 to count \(2\), got 0$"):
        sweep.run_shard(0, 2)
    with pytest.raises(hrm.InvalidInput, match=r"^count must be from 1 to 10000000, got 0$"):
        sweep.shard_runs(1, 0)
    with pytest.raises(hrm.InvalidInput, match=r"^count must be from 1 to 10000000, got 10000001$"):
        sweep.shard_runs(1, 10**7 + 1)
    assert sweep.config["settings"]["noise_levels"] == [0.0, 0.01] and sweep.scenario.duration == 0.1
    assert sweep.config["settings"]["controllers"] == ["pd", "fuzzy"] and sweep.config["settings"]["base_seed"] == 5
    with pytest.raises(hrm.InvalidInput, match="ascending"):
        hrm.Sweep("paper-responses-step", noise_levels=[0.01, 0.0], seeds=1)
    with pytest.raises(hrm.InvalidInput, match="seeds must be at least 1"):
        hrm.Sweep("paper-responses-step", noise_levels=[0.0], seeds=-1)
    # The bound `hrm sweep --seeds` has (the library's).
    with pytest.raises(hrm.InvalidInput, match="^seeds must be at most 1000000, got 2000000$"):
        hrm.Sweep("paper-responses-step", noise_levels=[0.0], seeds=2 * 10**6, controllers=["pd"])
    with pytest.raises(hrm.InvalidInput, match="must be one of"):
        hrm.Sweep("paper-responses-step", noise_levels=[0.0], seeds=1, controllers=["lqr?"])
    with pytest.raises(hrm.InvalidInput, match="^controllers lists pd twice$"):
        hrm.Sweep("paper-responses-step", noise_levels=[0.0], seeds=1, controllers=["pd", "fuzzy", "pd"])
    with pytest.raises(hrm.InvalidInput, match="^rate_noise_ratio must be finite and non-negative, got -1$"):
        hrm.Sweep("paper-responses-step", noise_levels=[0.0], seeds=1, rate_noise_ratio=-1.0)
    with pytest.raises(TypeError, match="^controllers must be a sequence of controller names, got a str$"):
        hrm.Sweep("paper-responses-step", noise_levels=[0.0], seeds=1, controllers="pd")
    with pytest.raises(TypeError, match=r"^controllers\[1\] must be a str, got an int$"):
        hrm.Sweep("paper-responses-step", noise_levels=[0.0], seeds=1, controllers=["pd", 3])
    with pytest.raises(hrm.InvalidInput, match="noise_levels"):
        hrm.Sweep("paper-responses-step", noise_levels=[i * 1e-6 for i in range(1001)], seeds=1)
    with pytest.raises(hrm.InvalidInput, match="more than the 1000000"):
        hrm.Sweep("paper-responses-step", noise_levels=[1e6], seeds=1, controllers=["pd"])


def test_shards_scheduled_by_concurrent_futures_merge_to_the_unsharded_sweep(tmp_path):
    """The pattern of docs/sweep.md's Dask example, with a thread pool: each task runs one shard
    (the GIL is released while it runs), and the merge equals the unsharded sweep bit for bit."""
    sweep = small_sweep()
    count = 3
    with concurrent.futures.ThreadPoolExecutor(max_workers=count) as pool:
        texts = list(pool.map(lambda k: sweep.run_shard(k, count), range(1, count + 1)))
    whole = sweep.run()
    assert hrm.Sweep.merge(texts) == whole
    # As files, in any order, or as the directory holding them.
    for k, text in enumerate(texts, start=1):
        (tmp_path / f"shard-{k}-of-{count}.json").write_text(text)
    assert hrm.Sweep.merge(reversed(sorted(tmp_path.iterdir()))) == whole
    assert hrm.Sweep.merge([tmp_path]) == whole
    cells = whole["cells"]
    assert [(c["noise_level"], c["controller"]) for c in cells] == [
        (0.0, "pd"), (0.0, "fuzzy"), (0.01, "pd"), (0.01, "fuzzy")]
    assert all(c["runs"] == 3 and c["failed"] == 0 for c in cells)
    # Without noise every seed gives the same run; with noise they differ.
    assert cells[0]["tip_error_rms_mm"]["std"] == 0.0 < cells[2]["tip_error_rms_mm"]["std"]


def test_the_merge_refuses_incomplete_or_foreign_shards():
    sweep = small_sweep()
    texts = [sweep.run_shard(k, 2) for k in (1, 2)]
    with pytest.raises(hrm.InvalidInput, match="shard 2/2 is missing"):
        hrm.Sweep.merge(texts[:1])
    with pytest.raises(hrm.InvalidInput, match="given twice"):
        hrm.Sweep.merge([texts[0], texts[0], texts[1]])
    other = hrm.Sweep(sweep.scenario, noise_levels=[0.0, 0.01], seeds=3, controllers=["pd", "fuzzy"], base_seed=6)
    with pytest.raises(hrm.InvalidInput, match="differ in base_seed"):
        hrm.Sweep.merge([texts[0], other.run_shard(2, 2)])
    with pytest.raises(hrm.InvalidInput, match="nothing to merge"):
        hrm.Sweep.merge([])
    # Texts an editor saved: a byte-order mark and CRLF line ends read as the same shards.
    edited = ["\ufeff" + text.replace("\n", "\r\n") for text in texts]
    assert hrm.Sweep.merge(edited) == hrm.Sweep.merge(texts)


def test_a_controller_file_changed_after_the_sweep_was_configured_is_refused(tmp_path):
    # The sweep records the .fis's SHA-256: a shard run with other contents (edited since, or
    # another copy where an unpickled sweep runs) would merge as the same sweep.
    fis = tmp_path / "mine.fis"
    fis.write_text(hrm.fuzzy.paper_controller().to_fis())
    scenario = hrm.Scenario.builtin("paper-tracking")
    scenario.duration = 0.02
    scenario.controller.fis = str(fis)
    sweep = hrm.Sweep(scenario, noise_levels=[0.0], seeds=2, controllers=["fuzzy"])
    first = sweep.run_shard(1, 2)
    shipped = pickle.dumps(sweep)
    fis.write_text(fis.read_text().replace("[-100]", "[-90]", 1))
    for stale in (sweep, pickle.loads(shipped)):
        with pytest.raises(hrm.InvalidInput, match=r"controller.fis \(.*mine.fis\) changed since the sweep was configured"):
            stale.run_shard(2, 2)
    # Configured again, it runs the new contents, and its shards do not merge with the old.
    again = hrm.Sweep(scenario, noise_levels=[0.0], seeds=2, controllers=["fuzzy"])
    with pytest.raises(hrm.InvalidInput, match="different contents of controller.fis"):
        hrm.Sweep.merge([first, again.run_shard(2, 2)])


def test_a_relative_controller_file_is_kept_absolute_and_versions_are_checked(tmp_path, monkeypatch):
    # A .fis given relative to the working directory is configured absolute, so that an
    # unpickled sweep run from elsewhere (a Dask worker) reads the same file.
    (tmp_path / "fisdir").mkdir()
    (tmp_path / "fisdir" / "c.fis").write_text(hrm.fuzzy.paper_controller().to_fis())
    monkeypatch.chdir(tmp_path)
    scenario = hrm.Scenario.builtin("paper-tracking")
    scenario.duration = 0.02
    scenario.controller.fis = "fisdir/c.fis"
    sweep = hrm.Sweep(scenario, noise_levels=[0.0], seeds=1, controllers=["fuzzy"])
    assert sweep.config["scenario"]["controller"]["fis"] == str(tmp_path / "fisdir" / "c.fis")
    shipped = pickle.dumps(sweep)
    monkeypatch.chdir(tmp_path / "fisdir")
    assert pickle.loads(shipped).run_shard(1, 1) == sweep.run_shard(1, 1)
    # A configuration another hrm version made reads back, but does not run under this one's name.
    config = json.loads(sweep.to_json())
    config["hrm_version"] = "9.9.9"
    other = hrm.Sweep.from_json(json.dumps(config))
    with pytest.raises(hrm.InvalidInput, match=r"^hrm_version: the sweep was configured by hrm 9\.9\.9"):
        other.run_shard(1, 1)


def test_a_shard_given_as_bytes_of_its_text_is_a_type_error():
    text = small_sweep().run_shard(1, 1)
    with pytest.raises(TypeError, match=r"^shards\[0\] is bytes holding a shard file's text, not a path"):
        hrm.Sweep.merge([text.encode()])


def test_sweeps_pickle_for_process_pools_and_clusters():
    sweep = small_sweep()
    clone = pickle.loads(pickle.dumps(sweep))
    assert clone.config == sweep.config
    assert hrm.Sweep.from_json(sweep.to_json()).config == sweep.config


def test_merge_equals_the_clis_summary_json(tmp_path):
    binary = hrm_binary()
    sweep = small_sweep()
    args = [binary, "sweep", "--scenario", "paper-responses-step", "--duration", "0.1", "--noise", "0,0.01",
            "--seeds", "3", "--controllers", "pd,fuzzy", "--base-seed", "5"]
    for k in (1, 2):
        subprocess.run(args + ["--shard", f"{k}/2", "--out", tmp_path / "shards"], check=True, capture_output=True)
    subprocess.run([binary, "sweep", "merge", "--out", tmp_path / "merged", tmp_path / "shards"], check=True,
                   capture_output=True)
    cli = json.loads((tmp_path / "merged" / "summary.json").read_text())
    # The command's shard files merge in Python to the command's summary, key for key.
    assert hrm.Sweep.merge([tmp_path / "shards"]) == cli
    python = sweep.run()
    assert python.keys() == cli.keys() and python["config"] == cli["config"]
    assert [c.keys() for c in python["cells"]] == [c.keys() for c in cli["cells"]]
