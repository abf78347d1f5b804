"""Studies on a real batch scheduler: the Slurm job array and merge job of docs/sweep.md, run as
written there with only the counts changed, on a single-node Slurm that the test starts
(Debian's slurm-wlm and munge), give the one-machine sweep's report bit for bit."""

import os
import pathlib
import re
import shlex
import shutil
import socket
import subprocess
import time

import pytest

from engines import require
from test_scenario import ROOT, hrm_binary

# The documented scripts' counts, scaled down for a 2-core machine: 3 shards of 1 core, 1 seed.
SBATCH_COUNTS = [
    ("#SBATCH --array=1-16", "#SBATCH --array=1-3"),
    ("#SBATCH --cpus-per-task=8", "#SBATCH --cpus-per-task=1"),
    ("N=16 ", "N=3 "),
    ("--seeds 200", "--seeds 1"),
]


def section(heading):
    """The text of docs/sweep.md under `## heading`, up to the next heading of that level."""
    text = (ROOT / "docs" / "sweep.md").read_text()
    assert f"## {heading}\n" in text, f"docs/sweep.md has no section '{heading}'"
    return text.split(f"## {heading}\n", 1)[1].split("\n## ", 1)[0]


def scaled(text, replacements):
    """`text` with each `(old, new)` replaced, each `old` standing exactly once in it."""
    for old, new in replacements:
        assert text.count(old) == 1, f"docs/sweep.md no longer holds {old!r} exactly once"
        text = text.replace(old, new)
    return text


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def run_quietly(args, **kwargs):
    return subprocess.run(args, capture_output=True, text=True, timeout=30, **kwargs)


def ensure_munge():
    """munged running with the package's key (the Debian package creates the key)."""
    if run_quietly(["munge", "-n"]).returncode == 0:
        return
    key = pathlib.Path("/etc/munge/munge.key")
    if not key.exists():
        subprocess.run(["runuser", "-u", "munge", "--", "mungekey", "--create"], check=True, timeout=30)
    run_dir = pathlib.Path("/run/munge")
    run_dir.mkdir(parents=True, exist_ok=True)
    shutil.chown(run_dir, "munge", "munge")
    subprocess.run(["runuser", "-u", "munge", "--", "munged"], check=True, timeout=30)
    for _ in range(50):
        if run_quietly(["munge", "-n"]).returncode == 0:
            return
        time.sleep(0.1)
    pytest.fail("munged did not start")


@pytest.fixture
def slurm(tmp_path):
    """A single-node Slurm cluster on loopback (its own configuration, ports and spool under
    `tmp_path`); yields the environment for its commands, and stops the daemons afterwards."""
    tools = ("slurmctld", "slurmd", "sbatch", "squeue", "sinfo", "munge", "munged")
    require(all(shutil.which(t) for t in tools), "Slurm (Debian's slurm-wlm and munge)")
    require(os.geteuid() == 0, "root, to start slurmd,")
    ensure_munge()
    base = tmp_path / "slurm"
    for sub in ("state", "spool", "log"):
        (base / sub).mkdir(parents=True)
    node = socket.gethostname().split(".")[0]
    conf = base / "slurm.conf"
    conf.write_text(f"""ClusterName=hrmtest
SlurmctldHost={node}(127.0.0.1)
SlurmUser=root
SlurmdUser=root
SlurmctldPort={free_port()}
SlurmdPort={free_port()}
AuthType=auth/munge
StateSaveLocation={base / 'state'}
SlurmdSpoolDir={base / 'spool'}
SlurmctldPidFile={base / 'slurmctld.pid'}
SlurmdPidFile={base / 'slurmd.pid'}
SlurmctldLogFile={base / 'log' / 'slurmctld.log'}
SlurmdLogFile={base / 'log' / 'slurmd.log'}
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
ReturnToService=2
MpiDefault=none
NodeName={node} NodeAddr=127.0.0.1 CPUs={os.cpu_count()} State=UNKNOWN
PartitionName=debug Nodes=ALL Default=YES MaxTime=INFINITE State=UP
""")
    env = dict(os.environ, SLURM_CONF=str(conf))
    daemons = [subprocess.Popen([d, "-D", "-f", str(conf)], env=env, stdout=subprocess.DEVNULL,
                                stderr=subprocess.DEVNULL) for d in ("slurmctld", "slurmd")]
    try:
        for _ in range(300):
            state = run_quietly(["sinfo", "-h", "-o", "%t"], env=env).stdout.strip()
            if state == "idle":
                break
            time.sleep(0.1)
        else:
            logs = "\n".join(p.read_text() for p in (base / "log").iterdir())
            pytest.fail(f"the Slurm node did not come up (state {state!r}):\n{logs[-3000:]}")
        yield env
    finally:
        run_quietly(["scancel", "--user=root"], env=env)
        for daemon in daemons:
            daemon.terminate()
        for daemon in daemons:
            try:
                daemon.wait(timeout=20)
            except subprocess.TimeoutExpired:
                daemon.kill()
                daemon.wait()


def test_the_documented_job_array_and_merge_give_the_one_machine_sweep(tmp_path, slurm):
    binary = hrm_binary()
    sbatch, submit = re.findall(r"```bash\n(.*?)```", section("Slurm job array"), re.S)
    sbatch = scaled(sbatch, SBATCH_COUNTS)
    work = tmp_path / "work"
    work.mkdir()
    (work / "sweep.sbatch").write_text(sbatch)
    (work / "submit-sweep.sh").write_text(submit)
    env = dict(slurm, PATH=f"{binary.parent}{os.pathsep}{slurm['PATH']}")
    # As the docs say: bash submit-sweep.sh in the folder holding both scripts.
    subprocess.run(["bash", "submit-sweep.sh"], cwd=work, env=env, check=True, timeout=60)
    deadline = time.monotonic() + 600
    while run_quietly(["squeue", "-h"], env=env).stdout.strip():
        if time.monotonic() > deadline:
            queue = run_quietly(["squeue"], env=env).stdout
            logs = "\n".join(p.read_text() for p in sorted((work / "logs").iterdir()))
            pytest.fail(f"the jobs did not finish in 600 s:\n{queue}\n{logs[-3000:]}")
        time.sleep(0.5)
    report = work / "sweep-report"
    logs = "\n".join(f"{p.name}: {p.read_text()}" for p in sorted((work / "logs").iterdir()))
    assert (report / "summary.json").is_file(), f"the merge job wrote no report; logs:\n{logs}"
    assert sorted(p.name for p in (work / "sweep-shards").glob("*.json")) == [
        f"shard-{k}-of-3.json" for k in (1, 2, 3)]
    # The same sweep on one machine: the array task's command without --shard and --out.
    command = re.search(r"hrm sweep (.*?)--shard", sbatch, re.S).group(1).replace("\\\n", " ")
    one = tmp_path / "one-machine"
    subprocess.run([binary, "sweep", *shlex.split(command), "--out", one], check=True,
                   capture_output=True, timeout=600)
    for name in ("summary.json", "runs.json", "table.txt"):
        assert (report / name).read_bytes() == (one / name).read_bytes(), name
