"""What a hostile or careless user does to `import hrm` (issue 32, docs/bad-input.md, "Python"):
fork after a parallel batch, unaligned and masked arrays, RAYON_NUM_THREADS, allocation
failures, Ctrl-C, the GIL during long work, huge base angles, shared results, pickling and
the messages of wrong arguments. Whatever could hang or kill the interpreter runs in a
subprocess with a timeout."""

import copy
import json
import math
import os
import pickle
import subprocess
import sys
import textwrap
import threading
import time
from pathlib import Path

import numpy as np
import pytest

import hrm

DOCS = Path(__file__).resolve().parents[3] / "docs"


def run_python(code, timeout=120, env=None):
    """Runs `code` in a fresh interpreter; returns the completed process (stdout, stderr)."""
    full_env = dict(os.environ)
    full_env.update(env or {})
    return subprocess.run([sys.executable, "-c", textwrap.dedent(code)], capture_output=True, text=True,
                          timeout=timeout, env=full_env)


def short_step(duration=0.05):
    scenario = hrm.Scenario.builtin("paper-responses-step")
    scenario.duration = duration
    return scenario


# --- fork after a parallel batch -----------------------------------------------------------------


def test_a_forked_child_runs_parallel_batches_after_the_parent_did(tmp_path):
    script = tmp_path / "fork.py"
    script.write_text(textwrap.dedent("""
        import multiprocessing, warnings
        import numpy as np
        import hrm

        warnings.simplefilter("ignore", DeprecationWarning)  # fork of a multi-threaded process

        def sweep():
            scenario = hrm.Scenario.builtin("paper-responses-step")
            scenario.duration = 0.02
            return hrm.Sweep(scenario, noise_levels=[0.0, 0.01], seeds=2, controllers=["pd"])

        def work(k):
            states = np.full((1024, 10), 0.01 * k)
            arm = hrm.Arm()
            model = hrm.ReducedModel(arm, alpha0=0.3)
            return (arm.gravity(states).sum(), model.gravity(np.full((1024, 2), 0.01 * k)).sum(),
                    hrm.fuzzy.paper_controller().eval(np.full((1024, 4), 0.01 * k)).sum(),
                    len(sweep().run_shard(1, 2)))

        if __name__ == "__main__":
            expected = [work(k) for k in range(4)]  # the parent's pool is running now
            with multiprocessing.get_context("fork").Pool(2) as pool:
                got = pool.map(work, range(4))
            assert got == expected, (got, expected)
            print("ok")
    """))
    done = subprocess.run([sys.executable, str(script)], capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == "ok"


# --- layouts: unaligned views, masked arrays ------------------------------------------------------


def packed(rows, width):
    """A packed structured array whose float64 field is unaligned (offset 1 byte)."""
    dtype = np.dtype([("flag", "u1"), ("x", "f8", (width,))], align=False)
    record = np.zeros(rows, dtype=dtype)
    record["x"] = np.linspace(0.0, 0.3, rows * width).reshape(rows, width)
    return record


def test_unaligned_views_are_read_as_copies():
    arm = hrm.Arm()
    record = packed(3, 10)
    one, batch = record[1]["x"], record["x"]
    assert one.flags.c_contiguous and not one.flags.aligned and not batch.flags.aligned
    np.testing.assert_array_equal(arm.gravity(one), arm.gravity(np.array(one)))
    np.testing.assert_array_equal(arm.rnea(batch, batch, batch), arm.rnea(*(np.array(batch),) * 3))
    np.testing.assert_array_equal(arm.aba(one, one, one), arm.aba(*(np.array(one),) * 3))
    model = hrm.ReducedModel(arm, alpha0=0.2)
    a = packed(2, 2)["x"]
    np.testing.assert_array_equal(model.fk(a), model.fk(np.array(a)))
    np.testing.assert_array_equal(model.forward_dynamics(a, a, a), model.forward_dynamics(*(np.array(a),) * 3))
    fis = hrm.fuzzy.paper_controller()
    x = packed(4, 4)["x"]
    np.testing.assert_array_equal(fis.eval(x), fis.eval(np.array(x)))
    lengths = packed(1, 3)[0]["x"] + 0.1
    np.testing.assert_array_equal(hrm.Arm(lengths=lengths).lengths, np.array(lengths))


def test_a_controller_may_return_an_unaligned_view():
    scenario = short_step(0.01)
    m = scenario.n_coords
    record = packed(1, m)

    def controller(t, a, a_dot, ref):
        record[0]["x"] = -2.0 * (a - ref.a) - 0.5 * a_dot
        return record[0]["x"]

    run = scenario.run(controller)
    assert run.failure is None and np.isfinite(run.tau_star).all()


def test_masked_arrays_are_refused_when_masked_and_read_when_not():
    arm = hrm.Arm()
    theta = np.ma.masked_array(np.full(10, 0.1), mask=[False] * 9 + [True])
    with pytest.raises(hrm.InvalidInput, match="theta is a masked array with masked entries"):
        arm.gravity(theta)
    with pytest.raises(hrm.InvalidInput, match="x is a masked array"):
        hrm.fuzzy.paper_controller().eval(np.ma.masked_invalid([0.0, np.nan, 0.0, 0.0]))
    with pytest.raises(hrm.InvalidInput, match="lengths is a masked array"):
        hrm.Arm(lengths=np.ma.masked_array([0.1, 0.1], mask=[True, False]))
    clear = np.ma.masked_array(np.full((3, 10), 0.1), mask=False)
    np.testing.assert_array_equal(arm.gravity(clear), arm.gravity(np.full((3, 10), 0.1)))


# --- threads, memory, signals ---------------------------------------------------------------------


@pytest.mark.parametrize("value", ["5000", "-1", "abc", "1e3"])
def test_a_bad_rayon_num_threads_is_a_clear_error_and_leaves_nothing_broken(value):
    done = run_python("""
        import os
        import numpy as np
        import hrm
        states = np.zeros((2000, 10))
        try:
            hrm.Arm().gravity(states)
        except hrm.InvalidInput as e:
            assert "RAYON_NUM_THREADS" in str(e), e
            print("refused:", e)
        os.environ["RAYON_NUM_THREADS"] = "2"
        assert (hrm.Arm().gravity(states) == hrm.Arm().gravity(states[:1])).all()
        print("ok")
    """, env={"RAYON_NUM_THREADS": value})
    assert done.returncode == 0, done.stderr
    assert "refused: RAYON_NUM_THREADS must be a number of threads from 0" in done.stdout
    assert done.stdout.strip().endswith("ok")


@pytest.mark.parametrize("value", ["0", "", "3"])
def test_a_valid_rayon_num_threads_works(value):
    done = run_python("""
        import numpy as np
        import hrm
        assert hrm.Arm().gravity(np.zeros((2000, 10))).shape == (2000, 10)
        print("ok")
    """, env={"RAYON_NUM_THREADS": value})
    assert done.returncode == 0 and done.stdout.strip() == "ok", done.stderr


@pytest.mark.skipif(sys.platform != "linux", reason="RLIMIT_AS and /proc are Linux's")
def test_an_allocation_the_system_refuses_is_a_memory_error():
    # 8 mass matrices of 4096 links: 1 GiB, within the documented limits, beyond the address
    # space left to the process.
    done = run_python("""
        import resource
        import numpy as np
        import hrm
        arm = hrm.Arm(links=4096)
        arm.gravity(np.zeros((600, 4096)))  # the pool's threads exist before the limit
        size = int(open("/proc/self/statm").read().split()[0]) * resource.getpagesize()
        resource.setrlimit(resource.RLIMIT_AS, (size + (256 << 20), resource.RLIM_INFINITY))
        try:
            arm.mass_matrix(np.zeros((8, 4096)))
        except MemoryError as e:
            print("MemoryError:", e)
        print(arm.gravity(np.zeros(4096)).shape)
    """)
    assert done.returncode == 0, done.stderr
    assert "MemoryError: the result of the batch: the system refused 1073741824 bytes" in done.stdout
    assert done.stdout.strip().endswith("(4096,)")


LIMITED = textwrap.dedent("""
    import resource
    import numpy as np
    import hrm

    def limited(headroom, call):
        # The address space in use now plus `headroom` bytes, for `call` only.
        size = int(open("/proc/self/statm").read().split()[0]) * resource.getpagesize()
        resource.setrlimit(resource.RLIMIT_AS, (size + headroom, resource.RLIM_INFINITY))
        try:
            call()
        except MemoryError as e:
            print("MemoryError:", e)
        else:
            print("no error")
        finally:
            resource.setrlimit(resource.RLIMIT_AS, (resource.RLIM_INFINITY, resource.RLIM_INFINITY))

    hrm.Arm(links=2).gravity(np.zeros((600, 2)))  # the pool's threads exist before any limit
""")


@pytest.mark.parametrize("setup, headroom, call, refused", [
    # The per-task workspaces of a parallel batch: 512 states of 500,000 links, the 2 GB result
    # given, not the workspaces' ~100 MB each.
    ("arm = hrm.Arm(links=500000); q = np.zeros((512, 500000))", "512 * 500000 * 8 + (40 << 20)",
     "arm.gravity(q)", "the workspace of the recursive algorithms: the system refused"),
    # A model's arrays: a million links' parameters and workspace.
    ("", "8 << 20", "hrm.Arm(links=1000000)", "the system refused"),
    # A run's record: 1.9 million samples of 71 numbers (below the 2^27 bound), about 1 GB.
    ("s = hrm.Scenario.builtin('paper-tracking'); s.duration = 1800.0; s.record_period = 0.001",
     "256 << 20", "s.run('pd')", "the run's record: the system refused"),
], ids=["batch-workspaces", "model-arrays", "run-record"])
def test_memory_the_system_refuses_is_a_memory_error_and_the_interpreter_goes_on(
        setup, headroom, call, refused):
    code = LIMITED + f"\n{setup}\nlimited({headroom}, lambda: {call})\nprint(hrm.Arm(links=3).gravity(np.zeros(3)).shape)\n"
    done = run_python(code, timeout=300, env={"RAYON_NUM_THREADS": "2"})
    assert done.returncode == 0, done.stderr
    assert "MemoryError:" in done.stdout and refused in done.stdout, done.stdout
    assert done.stdout.strip().endswith("(3,)")


INTERRUPT = textwrap.dedent("""
    import signal, threading, time, os
    import numpy as np
    import hrm

    # Python leaves SIGINT ignored when it starts ignored (a job started in the background by
    # a shell without job control): the test is of hrm's response to Ctrl-C, so it restores it.
    signal.signal(signal.SIGINT, signal.default_int_handler)

    def interrupted_after(call):
        timer = threading.Timer(0.3, os.kill, (os.getpid(), signal.SIGINT))
        start = time.monotonic()
        timer.start()
        try:
            call()
        except KeyboardInterrupt:
            print("interrupted after %.2f s" % (time.monotonic() - start))
        else:
            print("finished after %.2f s" % (time.monotonic() - start))
        timer.join()
""")


@pytest.mark.parametrize("setup, call", [
    ("model = hrm.ReducedModel(hrm.Arm(links=2000), harmonics=10); a = np.zeros((60000, 21))",
     "model.mass_matrix(a)"),
    ("model = hrm.ReducedModel(hrm.Arm(links=3000), harmonics=30); a = np.zeros((500, 61))",
     "model.mass_matrix(a)"),
    # Some 0.1 s of the curve's quadrature a state, far below the 2^24 operations of the
    # chain's terms from which a batch is interruptible.
    ("arm = hrm.SpatialArm(); a = np.full((400, 4), 30.0)", "arm.fk(a)"),
    ("s = hrm.Scenario.builtin('paper-tracking'); s.duration = 200.0", "s.run()"),
    ("s = hrm.Scenario.builtin('paper-responses-step'); s.duration = 2.0; "
     "sweep = hrm.Sweep(s, noise_levels=[0.0, 0.01], seeds=200, controllers=['fuzzy', 'pd'])", "sweep.run()"),
    # Some 4 s uninterrupted (a minute under MPC).
    ("s = hrm.Scenario.builtin('pipe-deploy'); s.duration = 60.0; s.record_period = 0.05",
     "s.run_deploy()"),
], ids=["parallel-batch", "serial-batch", "curve-quadrature-batch", "scenario-run", "sweep-run",
        "deploy-run"])
def test_ctrl_c_interrupts_long_calls_promptly(setup, call):
    code = INTERRUPT + f"\n{setup}\ndef call():\n    {call}\ninterrupted_after(call)\n"
    done = run_python(code, timeout=300)
    assert done.returncode == 0, done.stderr
    words = done.stdout.split()
    assert words[0] == "interrupted", done.stdout
    assert float(words[2]) < 1.0, done.stdout


def test_ctrl_c_while_an_argument_is_converted_is_a_keyboard_interrupt():
    class Interrupting:
        def __array__(self, dtype=None, copy=None):
            raise KeyboardInterrupt

        def __float__(self):
            raise KeyboardInterrupt

    arm = hrm.Arm()
    with pytest.raises(KeyboardInterrupt):
        arm.gravity(Interrupting())
    with pytest.raises(KeyboardInterrupt):
        hrm.Arm(link_length=Interrupting())
    with pytest.raises(KeyboardInterrupt):
        hrm.Arm(lengths=Interrupting())

    def controller(t, a, a_dot, ref):
        return Interrupting()

    with pytest.raises(KeyboardInterrupt):
        short_step(0.01).run(controller)


def progress_share(call):
    """The share of its free-running speed another Python thread keeps while `call` runs (about 1
    when `call` releases the GIL, near 0 when it holds it), and how long `call` took."""

    def counted_during(action):
        count, stop = [0], threading.Event()

        def counter():
            while not stop.is_set():
                count[0] += 1

        thread = threading.Thread(target=counter)
        thread.start()
        time.sleep(0.05)
        start, before = time.monotonic(), count[0]
        action()
        after, elapsed = count[0], time.monotonic() - start
        stop.set()
        thread.join()
        return (after - before) / elapsed, elapsed

    free, _ = counted_during(lambda: time.sleep(0.2))
    rate, elapsed = counted_during(call)
    return rate / free, elapsed


def test_long_one_object_calls_let_other_threads_run():
    arm = hrm.Arm(links=3000)
    models = []
    share, elapsed = progress_share(lambda: models.append(hrm.ReducedModel(arm, harmonics=150)))
    assert elapsed > 0.1 and share > 0.25, (share, elapsed)  # 0.03 with the GIL held
    # One-state calls on a larger model, long enough (about 0.1 s) to measure the share.
    model = hrm.ReducedModel(arm, harmonics=220)
    share, elapsed = progress_share(lambda: model.mass_matrix(np.zeros(model.n_coords)))
    assert elapsed > 0.05 and share > 0.25, (share, elapsed)


# --- wrong answers without an error --------------------------------------------------------------


@pytest.mark.parametrize("alpha0", [1e15, 1e17, 1e300, -7.0])
def test_ik_reduces_a_huge_base_angle(alpha0):
    model = hrm.ReducedModel(hrm.Arm(links=20, link_length=0.05))
    reduced = np.arctan2(np.sin(alpha0), np.cos(alpha0))
    target = model.fk([0.3, 0.2, reduced])
    a = model.ik(target, alpha0=alpha0)
    np.testing.assert_array_equal(a, model.ik(target, alpha0=reduced))
    assert abs(a[-1]) <= np.pi
    # The tip of the 20-link chain is within its discretisation error of the curve's end.
    assert np.linalg.norm(model.fk(a) - target) < 5e-3
    fixed = hrm.ReducedModel(hrm.Arm(links=20, link_length=0.05), alpha0=alpha0)
    assert fixed.alpha0 == reduced
    assert np.linalg.norm(fixed.fk(fixed.ik(target)) - target) < 5e-3


@pytest.mark.parametrize("harmonics, alpha0", [(2, 0.0), (2, 0.4), (3, -0.3)])
def test_k_harmonic_ik_solves_what_the_family_reaches(harmonics, alpha0):
    # 200 seeded targets m.fk(a), a in [-0.5, 0.5]^{2K}: some need |a2| beyond the K = 1
    # family's amplitude, where the closed-form start used to give Unreachable.
    model = hrm.ReducedModel(hrm.Arm(links=20, link_length=0.05), harmonics=harmonics, alpha0=alpha0)
    rng = np.random.default_rng(32)
    targets = model.fk(rng.uniform(-0.5, 0.5, (200, 2 * harmonics)))
    a = model.ik(targets)
    assert np.abs(model.fk(a) - targets).max() < 1e-5  # the chain's tip within its discretisation
    np.testing.assert_array_equal(a[17], model.ik(targets[17]))


def test_run_results_are_not_shared_mutable_objects():
    run = short_step(0.01).run("pd")
    for name in ["t", "a", "a_dot", "a_ref", "tau_star", "joint_torques", "tip", "tip_ref"]:
        array = getattr(run, name)
        assert not array.flags.writeable
        with pytest.raises(ValueError, match="read-only"):
            array[0] = 42
    first = run.t[0]
    summary = run.summary
    summary["rms_tip_error_mm"] = -1.0
    summary.clear()
    assert run.summary and run.summary != summary and run.t[0] == first


# --- pickling -------------------------------------------------------------------------------------


def round_trips(value):
    return [pickle.loads(pickle.dumps(value)), copy.deepcopy(value)]


def test_models_pickle_by_their_parameters():
    arm = hrm.Arm(lengths=[0.1, 0.2, 0.15], masses=[1.0, 0.5, 0.25], inertias=[1e-3, 2e-3, 3e-3], gravity=3.7)
    theta = np.array([0.1, -0.4, 0.3])
    for clone in round_trips(arm):
        np.testing.assert_array_equal(clone.mass_matrix(theta), arm.mass_matrix(theta))
        np.testing.assert_array_equal(clone.gravity(theta), arm.gravity(theta))
        assert repr(clone) == repr(arm)
    for model in [hrm.ReducedModel(arm, harmonics=1), hrm.ReducedModel(hrm.Arm(), harmonics=2, alpha0=0.4)]:
        a = np.linspace(0.1, 0.2, model.n_coords)
        for clone in round_trips(model):
            assert repr(clone) == repr(model)
            np.testing.assert_array_equal(clone.mass_matrix(a), model.mass_matrix(a))
            np.testing.assert_array_equal(clone.fk(a), model.fk(a))
    fis = hrm.fuzzy.paper_controller()
    x = np.random.default_rng(3).uniform(-1, 1, (50, 4))
    for clone in round_trips(fis):
        np.testing.assert_array_equal(clone.eval(x), fis.eval(x))
        assert clone.to_fis() == fis.to_fis()


def test_runs_settings_and_reference_samples_pickle():
    scenario = short_step(0.01)
    run = scenario.run("fuzzy")
    for clone in round_trips(run):
        for name in ["t", "a", "tau_star", "joint_torques", "tip"]:
            np.testing.assert_array_equal(getattr(clone, name), getattr(run, name))
        assert clone.summary == run.summary and clone.failure == run.failure
        assert clone.controller == run.controller and clone.coordinates == run.coordinates
        assert clone.view_html() == run.view_html()
    sine = hrm.Scenario.builtin("paper-responses-sine").reference
    for clone in round_trips(sine):
        assert clone.to_dict() == sine.to_dict()
        clone.amplitude = [0.2, 0.2]  # a view on a copy of the scenario
        assert sine.amplitude == [0.3, 0.15] and clone.amplitude == [0.2, 0.2]
    sample = hrm.ReferenceSample([0.1, 0.2], [0.0, 1.0], [2.0, 3.0])
    for clone in round_trips(sample):
        for name in ["a", "a_dot", "a_ddot"]:
            np.testing.assert_array_equal(getattr(clone, name), getattr(sample, name))
    with pytest.raises(hrm.InvalidInput, match="same length"):
        hrm.ReferenceSample([0.1], [0.0, 1.0], [2.0])


# --- messages -------------------------------------------------------------------------------------


def test_wrong_argument_types_name_the_argument():
    with pytest.raises(TypeError, match="^link_length must be a real number, got a bool$"):
        hrm.Arm(link_length=True)
    with pytest.raises(TypeError, match="^alpha0 must be a real number, got a bool$"):
        hrm.ReducedModel(hrm.Arm(links=10), alpha0=False)
    # numpy's bools are bools too (np.True_ built a 10 m arm as 1.0).
    with pytest.raises(TypeError, match="^link_length must be a real number, got a"):
        hrm.Arm(link_length=np.True_)
    with pytest.raises(hrm.InvalidInput, match=r"^harmonics must be a whole number, got a bool"):
        hrm.ReducedModel(hrm.Arm(links=10), harmonics=np.True_)
    with pytest.raises(TypeError, match="^link_length must be a real number, got a str$"):
        hrm.Arm(link_length="x")
    with pytest.raises(TypeError, match="^gravity must be a real number"):
        hrm.Arm(gravity=[1.0])
    with pytest.raises(hrm.InvalidInput, match=r"^lengths must be a 1-D sequence of numbers, got an array of shape \[2, 2\]"):
        hrm.Arm(lengths=np.ones((2, 2)))
    with pytest.raises(TypeError, match="^noise_levels must be a sequence of real numbers, got a str$"):
        hrm.Sweep("paper-responses-step", noise_levels="abc", seeds=1)
    with pytest.raises(hrm.InvalidInput, match=r"^controllers\[1\] must be one of fuzzy, pd, .*got 'zzz'$"):
        hrm.Sweep("paper-responses-step", noise_levels=[0.0], seeds=1, controllers=["pd", "zzz"])
    with pytest.raises(TypeError, match="^path_or_text must be a str or an os.PathLike, got an int$"):
        hrm.Scenario.from_toml(5)
    with pytest.raises(TypeError, match="^path_or_text must be a str or an os.PathLike"):
        hrm.fuzzy.System.from_fis(5)
    with pytest.raises(hrm.InvalidInput, match="^path_or_text is not a usable file name: .*surrogates not allowed"):
        hrm.fuzzy.System.from_fis("\ud800.fis")
    with pytest.raises(hrm.InvalidInput, match="^base_seed must be a whole number from 0 to 2\\^64 - 1, got -1$"):
        hrm.Sweep(short_step(), noise_levels=[0.0], seeds=1, base_seed=-1)
    with pytest.raises(TypeError, match="^base_seed must be a whole number, got a float$"):
        hrm.Sweep(short_step(), noise_levels=[0.0], seeds=1, base_seed=1.5)
    with pytest.raises(hrm.InvalidInput, match="^arm.links must be a whole number of at most 64 bits, got '3'$"):
        hrm.Arm(links="3")
    with pytest.raises(hrm.InvalidInput, match="^arm.links must be a whole number of at most 64 bits, got 3.0$"):
        hrm.Arm(links=3.0)
    for call in [lambda: hrm.Arm(links=True), lambda: hrm.SpatialArm(links=True),
                 lambda: hrm.Sweep(short_step(), noise_levels=[0.0], seeds=True)]:
        with pytest.raises(hrm.InvalidInput, match=r"^(arm\.links|seeds) must be a whole number, got a bool \(True\)$"):
            call()


def test_arguments_once_converted_by_pyo3_name_themselves():
    # alpha0, branch, the fuzzy check's options, the sweep's ratios and shards, a builtin's name:
    # a TypeError or InvalidInput whose message names the argument, not only its note.
    model = hrm.ReducedModel(hrm.Arm(links=10), alpha0=1.5)
    sweep = hrm.Sweep(short_step(0.01), noise_levels=[0.0], seeds=1, controllers=["pd"])
    system = hrm.fuzzy.paper_controller()
    cases = [
        (lambda: hrm.ReducedModel(hrm.Arm(links=10), alpha0="x"), TypeError, "^alpha0 must be a real number, got a str$"),
        (lambda: model.ik([0.3, 0.5], branch=1), TypeError, "^branch must be a str, got an int$"),
        (lambda: model.ik([0.3, 0.5], alpha0=[1.0]), TypeError, "^alpha0 must be a real number, got a list$"),
        (lambda: system.check(coverage="x"), TypeError, "^coverage must be a real number, got a str$"),
        (lambda: system.check(max_jump="y"), TypeError, "^max_jump must be a real number, got a str$"),
        (lambda: system.check(max_jump=-1.0), hrm.InvalidInput, "^max_jump must be positive and finite, got -1$"),
        (lambda: system.check(coverage=1e-200), hrm.InvalidInput,
         r"^analysis: coverage must give a threshold \(coverage, raised to the number of inputs under the product\) of at least 2\.2e-308, got 1e-200$"),
        (lambda: hrm.Sweep(short_step(), noise_levels=[0.0], seeds=1, rate_noise_ratio="x"), TypeError,
         "^rate_noise_ratio must be a real number, got a str$"),
        (lambda: sweep.shard_runs(-1, 2), hrm.InvalidInput, "^index must be at least 1, got -1$"),
        (lambda: sweep.run_shard(1, 2**70), hrm.InvalidInput, "^count must be a whole number of at most 64 bits"),
        (lambda: hrm.Scenario.builtin(5), TypeError, "^name must be a str, got an int$"),
        (lambda: hrm.ReferenceSample([float("nan")], [0.0], [0.0]), hrm.InvalidInput, "^a\\[0\\] must be finite"),
        (lambda: hrm.ReferenceSample([0.0], [float("inf")], [0.0]), hrm.InvalidInput, "^a_dot\\[0\\] must be finite"),
    ]
    for call, error, message in cases:
        with pytest.raises(error, match=message):
            call()
    # The defaults stand.
    assert sweep.shard_runs(1, 1) == list(range(sweep.n_runs))
    assert isinstance(system.check(), dict)
    assert len(model.ik([0.3, 0.5], branch="negative")) == 2


def test_merge_refuses_a_string():
    text = hrm.Sweep(short_step(0.01), noise_levels=[0.0], seeds=1, controllers=["pd"]).run_shard()
    with pytest.raises(TypeError, match=r"^shards must be a list .* got a str: give \[text\] for one shard$"):
        hrm.Sweep.merge(text)
    assert hrm.Sweep.merge([text])["cells"]


def test_merge_takes_bytes_paths_and_names_an_item_of_another_type(tmp_path):
    text = hrm.Sweep(short_step(0.01), noise_levels=[0.0], seeds=1, controllers=["pd"]).run_shard()
    (tmp_path / "shard-1-of-1.json").write_text(text)
    assert hrm.Sweep.merge([os.fsencode(tmp_path)]) == hrm.Sweep.merge([tmp_path])
    with pytest.raises(TypeError, match=r"^shards\[1\] must be a shard file's text, or a path \(str, bytes or os.PathLike\) .*, got a NoneType$"):
        hrm.Sweep.merge([tmp_path, None])


def test_every_controller_is_listed_in_the_docs():
    names = hrm.Sweep(short_step(0.01), noise_levels=[0.0], seeds=1).config["settings"]["controllers"]
    assert len(names) == 6
    python_md = (DOCS / "python.md").read_text()
    for name in names:
        assert f'"{name}"' in hrm.Scenario.run.__doc__, name
        assert f"`{name}`" in python_md or f'"{name}"' in python_md, name


# --- the spatial and URDF classes ------------------------------------------------------------------


def test_spatial_and_urdf_classes_follow_the_same_rules():
    from test_robot_engines import random_chain

    with pytest.raises(TypeError, match="^link_length must be a real number, got a str$"):
        hrm.SpatialArm(link_length="x")
    with pytest.raises(TypeError, match="^gravity must be a sequence of real numbers, got a str$"):
        hrm.SpatialArm(gravity="x")
    with pytest.raises(hrm.InvalidInput, match=r"^gravity must have 3 entries \(x, y, z\), got 1$"):
        hrm.SpatialArm(gravity=[1.0])
    with pytest.raises(hrm.InvalidInput, match=r"^inertias must be rows of three numbers, shape \(n, 3\)"):
        hrm.SpatialArm(inertias=[[1.0, 2.0]])
    with pytest.raises(hrm.InvalidInput, match=r"^arm\.lengths\[1\] is invalid: link 1: length must be such that the beam's inertia"):
        hrm.SpatialArm(lengths=[0.1, 1e300])
    with pytest.raises(hrm.InvalidInput, match=r"^arm\.link_length is invalid: link 0: length must be such that the beam's inertia"):
        hrm.SpatialArm(link_length=1e300)
    with pytest.raises(hrm.InvalidInput, match=r"^arm\.link_length is invalid: link 0: length must be such that the beam's inertia"):
        hrm.SpatialArm(link_length=5e-324)
    with pytest.raises(hrm.InvalidInput, match=r"^arm\.link_mass is invalid: link 0: mass must be such that the beam's inertia"):
        hrm.SpatialArm(link_mass=5e-324)
    with pytest.raises(hrm.InvalidInput, match=r"^arm is invalid: the chain's total mass"):
        hrm.SpatialArm(link_length=1e154)
    # An ik answer is one fk evaluates: from a guess of 10s, ik converges to coordinates whose
    # curve needs more quadrature nodes than fk allows.
    snake = hrm.SpatialArm(links=512, link_length=1e-3, harmonics=16)
    with pytest.raises(hrm.NumericalError, match=r"^the solution's curve \(.* cannot be evaluated by fk: the curve oscillates too fast"):
        snake.ik([0.1, 0.1, 0.1], guess=np.full(64, 10.0))
    # A per-link list and its scalar: refused (the scalar was silently unused); pickles keep
    # only the lists.
    for make in (hrm.Arm, hrm.SpatialArm):
        with pytest.raises(hrm.InvalidInput, match=r"^arm\.link_length = 7 is not used beside arm\.lengths"):
            make(link_length=7.0, lengths=[0.1, 0.1])
        with pytest.raises(hrm.InvalidInput, match=r"^arm\.link_mass = 0\.1 is not used beside arm\.masses"):
            make(link_mass=0.1, masses=[0.1, 0.2])
        arm = make(lengths=[0.1, 0.2], masses=[0.3, 0.4])
        assert np.array_equal(pickle.loads(pickle.dumps(arm)).lengths, arm.lengths)
    with pytest.raises(hrm.InvalidInput, match=r"base xyz must be at most 1000000000 m from the origin in each coordinate, got 1e308"):
        hrm.SpatialArm(base_xyz=[1e308, 0.0, 0.0])
    with pytest.raises(hrm.InvalidInput, match="^lengths is a masked array"):
        hrm.SpatialArm(lengths=np.ma.masked_array([0.1, 0.1], mask=[True, False]))
    urdf = random_chain(3, 4)
    with pytest.raises(hrm.InvalidInput, match=r"^gravity must have 3 entries \(x, y, z\), got 2$"):
        hrm.Chain.from_urdf(urdf, gravity=(0.0, -9.81))
    chain = hrm.Chain.from_urdf(urdf, gravity=np.array([0.0, -9.81, 0.0]))
    q = packed(3, chain.n_joints)["x"]
    np.testing.assert_array_equal(chain.gravity(q), chain.gravity(np.array(q)))
    for clone in round_trips(chain):
        np.testing.assert_array_equal(clone.mass_matrix(np.array(q)), chain.mass_matrix(np.array(q)))
    arm = hrm.SpatialArm(links=4, inertias=np.full((4, 3), 1e-3), base_rpy=[0.1, 0.2, 0.3])
    a = packed(2, arm.n_coords)["x"]
    for clone in round_trips(arm):
        np.testing.assert_array_equal(clone.fk(a), arm.fk(np.array(a)))


def test_messages_write_tiny_and_huge_numbers_compactly():
    # A library writes 1e-300 through lane_math::Compact; any message is compacted once more at
    # the exception: never a decimal of hundreds of digits.
    for call, number in [
        (lambda: hrm.Arm(links=3, link_length=1e-300), "1e-300"),
        (lambda: hrm.Arm(links=3, link_length=1e300), "1e300"),
        (lambda: hrm.Arm(links=3, link_mass=5e-324), "5e-324"),
    ]:
        with pytest.raises(hrm.InvalidInput) as error:
            call()
        message = str(error.value)
        assert number in message and len(message) < 300, message
    scenario = short_step()
    scenario.limits.max_modal_error = 1e-300
    run = scenario.run("pd")
    assert run.failure is not None and "1e-300" in run.failure and len(run.failure) < 300, run.failure


def test_broadcast_views_are_bounded_before_any_copy():
    # A broadcast view of 8 bytes stands for billions of values: refused by its size, never
    # copied (the copy aborted the interpreter).
    huge = np.broadcast_to(0.0, (10**10,))
    with pytest.raises(hrm.InvalidInput, match="^gravity has 10000000000 values, more than the limit of 3$"):
        hrm.SpatialArm(gravity=huge)
    with pytest.raises(hrm.InvalidInput, match="^lengths has 1000000000 values, more than the limit of"):
        hrm.Arm(lengths=np.broadcast_to(np.ones(1), (10**9,)))
    with pytest.raises(hrm.InvalidInput, match="^theta has 4000000000 values, more than the limit of 268435456$"):
        hrm.Arm(links=5).gravity(np.broadcast_to(np.zeros(4, dtype=np.int64), (10**9, 4)))


def test_rates_and_spatial_gravity_are_read_as_hrm_eval_reads_them():
    # Rates beyond the scale a run resolves, refused by the same check as hrm eval's (1e7 rad/s
    # gave accelerations of 1e14 here while eval refused it); a batch names the state.
    arm = hrm.Arm(links=3)
    unit = r"in magnitude \(rad/s, m/s for a prismatic joint\), got "
    with pytest.raises(hrm.InvalidInput, match=r"^theta_dot\[0\] must be at most 1000000 " + unit + "10000000$"):
        arm.coriolis([0.0, 0.0, 0.0], [1e7, 0.0, 0.0])
    with pytest.raises(hrm.InvalidInput, match=r"^theta_dot\[1, 2\] must be at most 1000000 " + unit):
        arm.aba(np.zeros((2, 3)), np.array([[0.0, 0.0, 0.0], [0.0, 0.0, -2e6]]), np.zeros((2, 3)))
    with pytest.raises(hrm.InvalidInput, match=r"^a_dot\[3\] must be at most 1000000 " + unit):
        hrm.SpatialArm().forward_dynamics([0.1] * 4, [0.0, 0.0, 0.0, 1e7], [0.0] * 4)
    with pytest.raises(hrm.InvalidInput, match=r"^a_dot\[0\] must be at most 1000000 "):
        hrm.ReducedModel(hrm.Arm(links=10)).forward_dynamics([0.1] * 3, [-1e300, 0.0, 0.0], [0.0] * 3)
    assert np.all(np.isfinite(arm.coriolis([0.0, 0.0, 0.0], [1e6, -1e6, 0.0])))
    # One number as a spatial arm's gravity: g along -z, as a scenario and hrm eval read it.
    for g in (9.81, np.float64(9.81), np.float32(9.81), np.array(9.81), 3):
        expected = (0.0, 0.0, -float(np.float64(g)))
        assert hrm.SpatialArm(links=2, gravity=g).gravity == expected, g
    with pytest.raises(hrm.InvalidInput, match=r"^arm\.gravity must be"):
        hrm.SpatialArm(gravity=1e7)
    for flag in (True, np.bool_(False), np.array(True)):
        with pytest.raises(TypeError, match=r"^gravity must be a number g or a vector \(x, y, z\), got a "):
            hrm.SpatialArm(gravity=flag)
        with pytest.raises(TypeError, match=r"^gravity must be a number g or a vector \(x, y, z\), got a "):
            hrm.Chain.from_urdf(hrm.SpatialArm(links=2).to_urdf(), gravity=flag)
    # A URDF chain reads one number as the spatial arm does; zero gravity is +0, not -0.
    urdf = hrm.SpatialArm(links=2).to_urdf()
    assert hrm.Chain.from_urdf(urdf, gravity=9.81).gravity_vector == (0.0, 0.0, -9.81)
    assert hrm.Chain.from_urdf(urdf).gravity_vector == (0.0, 0.0, -9.81)
    for zero in (hrm.SpatialArm(gravity=0).gravity[2], hrm.Chain.from_urdf(urdf, gravity=0.0).gravity_vector[2]):
        assert zero == 0.0 and math.copysign(1.0, zero) == 1.0
    # A reference sample's rate, as a run's reference would reach it.
    with pytest.raises(hrm.InvalidInput, match=r"^a_dot\[2\] must be at most 1000000 " + unit):
        hrm.ReferenceSample(np.zeros(3), [0.0, 0.0, 1e7], np.zeros(3))
    with pytest.raises(hrm.InvalidInput, match=r"^gravity must have 3 entries \(x, y, z\), got 1$"):
        hrm.SpatialArm(gravity=np.array([9.81]))


def test_modal_coordinates_are_bounded_as_a_run_bounds_them():
    # A mode of 1e17 rounds the others away in theta = J a + theta_0: refused beyond the 1e6
    # at which a run stops, as hrm eval refuses it; a batch names the state.
    unit = r" must be at most 1000000 in magnitude \(rad\), got "
    reduced = hrm.ReducedModel(hrm.Arm(links=10))
    with pytest.raises(hrm.InvalidInput, match=r"^a\[1\]" + unit + "1e17$"):
        reduced.joint_angles([0.1, 1e17, 0.0])
    with pytest.raises(hrm.InvalidInput, match=r"^a\[1, 0\]" + unit + "-2000000$"):
        reduced.fk(np.array([[0.1, 0.2, 0.0], [-2e6, 0.0, 0.0]]))
    with pytest.raises(hrm.InvalidInput, match=r"^a\[3\]" + unit):
        hrm.SpatialArm().forward_dynamics([0.1, 0.0, 0.0, 1e300], [0.0] * 4, [0.0] * 4)
    with pytest.raises(hrm.InvalidInput, match=r"^a\[0\]" + unit):
        hrm.ReferenceSample([1e7, 0.0], np.zeros(2), np.zeros(2))
    # A NaN is named by the argument too (it was "modal coordinates[0] must be finite").
    with pytest.raises(hrm.InvalidInput, match=r"^a\[0\] must be finite, got NaN$"):
        reduced.fk([float("nan"), 0.0, 0.0])
    with pytest.raises(hrm.InvalidInput, match=r"^harmonics must be at least 1, got 0$"):
        hrm.ReducedModel(hrm.Arm(links=10), harmonics=0)
    with pytest.raises(hrm.InvalidInput, match=r"^a_dot\[1, 2\] must be finite, got inf$"):
        reduced.forward_dynamics(np.zeros((2, 3)), [[0.0] * 3, [0.0, 0.0, np.inf]], np.zeros((2, 3)))
    # At the bound the answer is the arithmetic's: theta = J a + theta_0 to rounding.
    a = np.array([1e6, -1e6, 0.5])
    assert np.allclose(reduced.joint_angles(a), reduced.jacobian @ a, rtol=0, atol=1e-9)


def test_a_sweep_of_too_much_work_is_refused_until_split_into_shards():
    # Ten million runs of 2 s: refused at once; a shard of ten of them runs.
    levels = [0.01 * k for k in range(10)]
    sweep = hrm.Sweep("paper-responses-step", noise_levels=levels, seeds=10**6, controllers=["pd"])
    with pytest.raises(hrm.InvalidInput, match=r"^runs: the 10000000 runs of shard 1/1 would take an estimated .* more than the 1e14 one shard may take"):
        sweep.run()
    lines = sweep.run_shard(3, 10**6).splitlines()
    assert len(lines) == 11
    assert json.loads(lines[0])["shard"] == {"index": 3, "count": 10**6}
