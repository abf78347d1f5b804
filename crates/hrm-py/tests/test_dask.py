"""Studies on Dask: the pattern of docs/sweep.md's Dask section, run as written there with only
the counts changed, on a local cluster of worker processes, gives the one-machine sweep bit for
bit."""

import importlib.util
import re

from engines import require
from test_slurm import scaled, section


def test_the_documented_dask_pattern_on_worker_processes_equals_the_one_machine_sweep():
    require(importlib.util.find_spec("distributed") is not None, 'Dask ("dask[distributed]" from PyPI)')
    from dask.distributed import LocalCluster

    (code,) = re.findall(r"```python\n(.*?)```", section("Dask"), re.S)
    code = scaled(code, [
        ('Client("scheduler-address:8786")', "Client(cluster)"),
        ("seeds=200", "seeds=1"),
        ("count = 64", "count = 3"),
    ])
    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True, host="127.0.0.1",
                      dashboard_address=None) as cluster:
        namespace = {"cluster": cluster}
        exec(compile(code, "docs/sweep.md", "exec"), namespace)
        client = namespace["client"]
        try:
            # The shards ran in the two worker processes, not in this one.
            assert len(client.scheduler_info()["workers"]) == 2
        finally:
            client.close()
    sweep, summary = namespace["sweep"], namespace["summary"]
    assert len(summary["cells"]) == 6 * 6
    assert summary == sweep.run()
