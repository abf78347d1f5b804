"""Scenarios and closed-loop runs: settings as attributes, built-in and Python controllers, the
paper's tracking figures, runs that stop, and the summary against the `hrm` command's."""

import json
import math
import pickle
import pathlib
import subprocess

import numpy as np
import pytest

import hrm

ROOT = pathlib.Path(__file__).resolve().parents[3]


def hrm_binary():
    """The `hrm` command built by `cargo test` (debug) or `cargo build --release`, if any."""
    for profile in ("debug", "release"):
        path = ROOT / "target" / profile / "hrm"
        if path.is_file():
            return path
    pytest.skip("the hrm binary is not built (cargo build -p hrm-cli)")


def short_step(duration=0.2):
    scenario = hrm.Scenario.builtin("paper-responses-step")
    scenario.duration = duration
    return scenario


def fuzzy_in_python():
    """The paper's fuzzy controller as a Python callable: inputs (a - a_ref, a_dot), as the
    built-in controller forms them (eqs 22-24)."""
    system = hrm.fuzzy.paper_controller()

    def controller(t, a, a_dot, ref):
        return system.eval(np.concatenate([a - ref.a, a_dot]))

    return controller


def test_builtin_names_and_toml_round_trip(tmp_path):
    assert "paper-tracking" in hrm.Scenario.builtin_names()
    scenario = hrm.Scenario.builtin("paper-tracking")
    text = scenario.to_toml()
    assert hrm.Scenario.from_toml(text).to_toml() == text
    path = tmp_path / "s.toml"
    path.write_text(text)
    assert hrm.Scenario.from_toml(path).to_dict() == scenario.to_dict()
    assert hrm.Scenario.from_toml(str(path)).to_dict() == scenario.to_dict()
    with pytest.raises(hrm.InvalidInput, match="neither a built-in scenario"):
        hrm.Scenario.builtin("no-such")
    with pytest.raises(FileNotFoundError):
        hrm.Scenario.from_toml(tmp_path / "missing.toml")
    with pytest.raises(hrm.InvalidInput, match="line 2"):
        hrm.Scenario.from_toml('name = "x"\nduration = = 1\n')


def test_settings_read_and_write_through():
    scenario = hrm.Scenario.builtin("paper-tracking")
    assert scenario.duration == 5.5 and scenario.name == "paper-tracking"
    assert scenario.arm.links == 10 and scenario.reference.sine.amplitude == 0.4
    assert scenario.controller.kind == "fuzzy" and scenario.initial is None
    assert scenario.n_coords == 2 and scenario.coordinate_names == ["a1", "a2"]
    scenario.duration = 0.5
    scenario.arm.links = 12
    scenario.reference.sine.amplitude = np.float64(0.3)
    scenario.noise.sensor_a_std = np.array([1e-3, 2e-3], dtype=np.float32)
    scenario.controller.kp = (100, 200)
    scenario.seed = 2**64 - 1  # beyond TOML's integers: written as a decimal string
    assert scenario.duration == 0.5 and scenario.arm.links == 12
    assert scenario.reference.sine.amplitude == 0.3
    assert scenario.noise.sensor_a_std == [float(np.float32(1e-3)), float(np.float32(2e-3))]
    assert scenario.controller.kp == [100.0, 200.0]
    assert hrm.Scenario.from_toml(scenario.to_toml()).to_dict() == scenario.to_dict()
    assert scenario.seed == str(2**64 - 1)
    # Any other integer setting stops at TOML's largest integer, named.
    for table, key in [(scenario.arm, "links"), (scenario.modal, "harmonics")]:
        with pytest.raises(hrm.InvalidInput, match=rf"^\w+\.{key} must be at most 9223372036854775807 \(the largest integer a scenario setting holds\), got 9223372036854775808$"):
            setattr(table, key, 2**63)
    scenario.initial = {"a": [0.1, 0.0]}
    assert scenario.initial.a == [0.1, 0.0] and scenario.initial.a_dot is None
    del scenario.initial
    assert scenario.initial is None
    copy = scenario.copy()
    copy.duration = 1.0
    assert scenario.duration == 0.5


def test_a_view_of_a_table_the_scenario_no_longer_has_is_refused():
    scenario = hrm.Scenario.builtin("paper-tracking")
    sine = scenario.reference.sine
    assert sine.amplitude is not None
    scenario.reference = {"kind": "step", "target": [0.2, -0.2], "time": 0.1}
    import copy
    import pickle

    for read in (lambda: sine.amplitude, sine.to_dict, lambda: pickle.dumps(sine), lambda: copy.deepcopy(sine)):
        with pytest.raises(hrm.InvalidInput, match="^reference.sine: the scenario has no such table$"):
            read()


def test_settings_are_checked_with_the_library_messages():
    scenario = hrm.Scenario.builtin("paper-tracking")
    with pytest.raises(hrm.InvalidInput, match="^duration: .*f64"):
        scenario.duration = "long"
    with pytest.raises(hrm.InvalidInput, match="unknown field `durration`"):
        scenario.durration = 1.0
    with pytest.raises(hrm.InvalidInput, match="^arm.linkz: unknown field `linkz`, expected one of `kind`, .*`links`"):
        scenario.arm.linkz = 3
    with pytest.raises(hrm.InvalidInput, match="missing field `duration`"):
        del scenario.duration
    with pytest.raises(AttributeError, match="no setting arm.colour"):
        scenario.arm.colour
    with pytest.raises(AttributeError):
        scenario.colour
    with pytest.raises(hrm.InvalidInput, match="cannot be set to a object"):
        scenario.duration = object()
    # Hostile values are refused before they are converted: deep nesting, huge lists.
    deep = []
    for _ in range(100_000):
        deep = [deep]
    with pytest.raises(hrm.InvalidInput, match="arm.lengths is nested more than 16 levels deep"):
        scenario.arm.lengths = deep
    for huge in ([0.1] * (2**20 + 1), np.full(2**20 + 1, 0.1)):
        with pytest.raises(hrm.InvalidInput, match="has 1048577 items, more than the 1048576"):
            scenario.arm.lengths = huge
    assert scenario.duration == 5.5 and scenario.arm.lengths is None  # refused writes change nothing
    # Domains are checked when the scenario is run, with the messages of `hrm simulate`.
    scenario.duration = -1.0
    with pytest.raises(hrm.InvalidInput, match="duration must be positive and finite, got -1"):
        scenario.run()
    scenario.duration = 0.1
    scenario.controller.kp = [1.0, 2.0, 3.0]
    with pytest.raises(hrm.InvalidInput, match="controller.kp has 3 entries"):
        scenario.run("computed-torque")
    with pytest.raises(hrm.InvalidInput, match="fuzzy, pd, computed-torque, fuzzy-gc"):
        scenario.run("bang-bang")
    with pytest.raises(hrm.InvalidInput, match="callable"):
        scenario.run(42)


def test_run_arrays_and_summary():
    scenario = short_step()
    run = scenario.run("computed-torque")
    k, m = len(run.t), 2
    assert run.failure is None and run.controller == "computed-torque"
    assert run.coordinates == ["a1", "a2"]
    for name, width in [("a", m), ("a_dot", m), ("a_ref", m), ("tau_star", m), ("joint_torques", 10),
                        ("tip", 2), ("tip_ref", 2)]:
        array = getattr(run, name)
        assert array.shape == (k, width) and array.dtype == np.float64, name
    assert run.summary["recorded_samples"] == k
    assert math.isclose(run.t[-1], scenario.duration)
    # The summary is the time series' own: tip error RMS and maximum, modal error maximum.
    tip_error = np.hypot(*(run.tip - run.tip_ref).T)
    assert math.isclose(run.summary["tip_error_rms_m"], np.sqrt(np.mean(tip_error**2)), rel_tol=1e-12)
    assert math.isclose(run.summary["tip_error_max_m"], tip_error.max(), rel_tol=1e-14)
    assert run.summary["modal_error_max_rad"] == list(np.abs(run.a - run.a_ref).max(axis=0))
    # The joint torques are tau = M J a_ddot + C + G with J^T tau = tau* (eq 14).
    model = hrm.ReducedModel(hrm.Arm(), alpha0=scenario.alpha0)
    assert np.allclose(run.joint_torques @ model.jacobian, run.tau_star, atol=1e-9)


def test_the_papers_tracking_figures_through_python():
    """Fuzzy control of paper-tracking: 4.8313 mm tip RMS and 6.6222 mm maximum (pinned), and a
    Python callable computing the same fuzzy law gives the same run bit for bit."""
    scenario = hrm.Scenario.builtin("paper-tracking")
    builtin = scenario.run("fuzzy")
    assert f"{builtin.summary['tip_error_rms_m'] * 1e3:.4f}" == "4.8313"
    assert f"{builtin.summary['tip_error_max_m'] * 1e3:.4f}" == "6.6222"
    python = scenario.run(fuzzy_in_python())
    assert python.controller == "python" and python.failure is None
    for name in ["t", "a", "a_dot", "a_ref", "tau_star", "joint_torques", "tip", "tip_ref"]:
        assert np.array_equal(getattr(python, name), getattr(builtin, name)), name
    assert python.summary == builtin.summary


def test_a_python_controller_sees_the_measured_state_and_the_reference():
    scenario = short_step(0.05)
    seen = []

    def spy(t, a, a_dot, ref):
        seen.append((t, a.copy(), a_dot.copy(), ref.a.copy(), ref.a_dot.copy(), ref.a_ddot.copy()))
        return -400.0 * (a - ref.a) - 20.0 * a_dot

    run = scenario.run(spy)
    # One call per controller sample (period 1e-4 s here, recorded every 1e-3 s).
    assert len(seen) == run.summary["controller_samples"]
    times = np.array([s[0] for s in seen])
    assert np.allclose(np.diff(times), scenario.controller.period)
    recorded = {round(t, 9): i for i, t in enumerate(run.t)}
    for t, a, a_dot, ref_a, _, _ in seen:
        if round(t, 9) in recorded:
            row = recorded[round(t, 9)]
            assert np.array_equal(a, run.a[row]) and np.array_equal(a_dot, run.a_dot[row])
            assert np.array_equal(ref_a, run.a_ref[row])
            assert np.allclose(run.tau_star[row], -400.0 * (a - ref_a) - 20.0 * a_dot)


def test_an_exception_in_the_controller_propagates_with_its_traceback():
    class Tired(RuntimeError):
        pass

    def failing_controller(t, a, a_dot, ref):
        if t >= 0.01:
            raise Tired(f"tired at t = {t:.4f}")
        return np.zeros(2)

    with pytest.raises(Tired, match="tired at t = 0.0100") as caught:
        short_step().run(failing_controller)
    assert any(entry.name == "failing_controller" for entry in caught.traceback)


@pytest.mark.parametrize(
    "returned, error, message",
    [
        (np.zeros(3), hrm.InvalidInput, r"return value at t = 0 s: tau_star has 3 entries, expected 2"),
        (np.zeros((1, 2)), hrm.InvalidInput, r"tau_star must have shape \(2,\), got an array of shape \[1, 2\]"),
        (np.zeros((2, 1)), hrm.InvalidInput, r"tau_star must have shape \(2,\), got an array of shape \[2, 1\]"),
        ("abc", hrm.InvalidInput, r"return value at t = 0 s: tau_star must hold real numbers"),
        (np.array([1j, 0]), hrm.InvalidInput, "tau_star must hold real numbers"),
        (None, hrm.InvalidInput, "tau_star"),
        (np.array([np.nan, 0.0]), hrm.NumericalError, r"non-finite tau_star \[NaN, 0.0\] at t = 0 s"),
    ],
)
def test_a_controller_returning_nonsense_is_a_clear_error(returned, error, message):
    with pytest.raises(error, match=message):
        short_step().run(lambda t, a, a_dot, ref: returned)


def test_a_controller_may_return_lists_and_float32():
    a = short_step(0.02).run(lambda t, a, a_dot, ref: [0.5, -0.25])
    b = short_step(0.02).run(lambda t, a, a_dot, ref: np.array([0.5, -0.25], dtype=np.float32))
    assert np.array_equal(a.a, b.a) and np.all(a.tau_star == [0.5, -0.25])


def paper_jacobian():
    """J of the paper's arm (10 links of 0.1 m and 0.1 kg, K = 1, alpha0 = pi/2), shape (10, 2)."""
    arm = hrm.Arm(links=10, link_length=0.1, link_mass=0.1)
    return hrm.ReducedModel(arm, harmonics=1, alpha0=np.pi / 2).jacobian


def test_a_disturbance_is_its_modal_force_added_to_the_controllers():
    scenario = short_step(0.1)
    tau_d = 0.02 * (np.arange(10) - 3.5)
    force = paper_jacobian().T @ tau_d

    def pd(t, a, a_dot, ref):
        return -400.0 * (a - ref.a) - 20.0 * a_dot

    seen = []

    def push(t, a, a_dot):
        seen.append((t, a.copy()))
        return tau_d if t >= 0.05 else None

    pushed = scenario.run(pd, disturbance=push)
    added = scenario.run(lambda t, a, a_dot, ref: pd(t, a, a_dot, ref) + (force if t >= 0.05 else 0.0))
    plain = scenario.run(pd)
    np.testing.assert_allclose(pushed.a, added.a, rtol=1e-12, atol=1e-15)
    after = pushed.t > 0.05 + 1e-9
    assert np.array_equal(pushed.a[~after], plain.a[~after]) and not np.allclose(pushed.a[after], plain.a[after])
    # The recorded joint torques are the actuators': the push subtracted.
    pushing = (pushed.t >= 0.05 - 1e-12)[:, None]
    np.testing.assert_allclose(pushed.joint_torques + pushing * tau_d, added.joint_torques, rtol=1e-9, atol=1e-12)
    # Called once per controller sample, in order, with the true state.
    assert len(seen) == pushed.summary["controller_samples"]
    assert np.all(np.diff([t for t, _ in seen]) > 0)
    recorded = {round(t, 9): i for i, t in enumerate(pushed.t)}
    for t, a in seen:
        if round(t, 9) in recorded:
            assert np.array_equal(a, pushed.a[recorded[round(t, 9)]])
    # With a built-in controller too, and a disturbance of None changes nothing.
    assert scenario.run("pd", disturbance=lambda t, a, a_dot: None).summary == scenario.run("pd").summary
    assert scenario.run("pd", disturbance=push).summary != scenario.run("pd").summary


def test_a_disturbance_raising_or_returning_nonsense_is_a_clear_error():
    class Slipped(RuntimeError):
        pass

    def slipping(t, a, a_dot):
        if t >= 0.01:
            raise Slipped("slipped")
        return None

    with pytest.raises(Slipped, match="slipped"):
        short_step(0.05).run("pd", disturbance=slipping)
    with pytest.raises(hrm.InvalidInput, match=r"disturbance's return value at t = 0 s: tau has 2 entries, expected 10"):
        short_step(0.05).run(disturbance=lambda t, a, a_dot: np.zeros(2))
    with pytest.raises(hrm.NumericalError, match="non-finite joint torque"):
        short_step(0.05).run(disturbance=lambda t, a, a_dot: np.full(10, np.inf))
    with pytest.raises(hrm.InvalidInput, match="disturbance must be None or a callable"):
        short_step(0.05).run(disturbance=3.0)


def test_a_run_that_diverges_keeps_its_data_up_to_the_stop():
    scenario = short_step(0.5)
    scenario.limits.max_modal_error = 0.05
    for controller in ["pd", lambda t, a, a_dot, ref: np.zeros(2)]:
        run = scenario.run(controller)
        assert run.failure is not None and "runaway tracking error" in run.failure
        assert run.summary["error"] == run.failure
        assert run.summary["stopped_at_s"] == run.t[-1] < 0.5
        assert np.abs(run.a[-1] - run.a_ref[-1]).max() > 0.05
        assert np.abs(run.a[:-1] - run.a_ref[:-1]).max() <= 0.05
        assert len(run.t) == run.summary["recorded_samples"]


def test_a_run_that_stops_before_its_first_sample_is_a_run_without_rows():
    # A first torque that overflows the dynamics: the integrator fails inside the first step.
    run = short_step(0.5).run(lambda t, a, a_dot, ref: np.full(2, 1e200))
    assert run.failure is not None and run.failure.startswith(
        "integration diverged under the held modal force tau* = [1e200, 1e200] N m: "
    )
    assert run.summary["error"] == run.failure and run.summary["recorded_samples"] == 0
    # Statistics over no recorded sample are None, not zeros.
    for key in ("tip_error_rms_m", "tip_error_max_m", "modal_error_rms_rad", "modal_error_max_rad"):
        assert run.summary[key] is None, key
    assert run.t.shape == (0,) and run.a.shape == (0, 2) and run.tip.shape == (0, 2)
    with pytest.raises(hrm.InvalidInput, match="no sample to show"):
        run.view_html()
    assert run._repr_html_() is None and "stopped" in repr(run)
    clone = pickle.loads(pickle.dumps(run))
    assert clone.failure == run.failure and clone.t.shape == (0,)


def assert_close(actual, expected):
    """Equal structure, numbers to 1e-12 relative (the command is a debug build, the package a
    release one)."""
    if isinstance(expected, dict):
        assert actual.keys() == expected.keys()
        for key in expected:
            assert_close(actual[key], expected[key])
    elif isinstance(expected, list):
        assert len(actual) == len(expected)
        for x, y in zip(actual, expected):
            assert_close(x, y)
    elif isinstance(expected, float):
        assert math.isclose(actual, expected, rel_tol=1e-12, abs_tol=1e-15), (actual, expected)
    else:
        assert actual == expected


def simulate_with_the_cli(scenario, controller, out):
    """`hrm simulate` on the scenario; a run that stops exits with 1 after writing its files."""
    out.mkdir()
    path = out / "scenario.toml"
    path.write_text(scenario.to_toml())
    subprocess.run([hrm_binary(), "simulate", "--scenario", path, "--controller", controller, "--out",
                    out / "run"], check=False, capture_output=True)
    return json.loads((out / "run" / "summary.json").read_text())


def test_summary_equals_the_clis_summary_json(tmp_path):
    scenario = short_step(0.3)
    cli = simulate_with_the_cli(scenario, "fuzzy-gc", tmp_path / "ok")
    python = scenario.run("fuzzy-gc").summary
    assert python.keys() == cli.keys()
    assert_close(python, cli)
    # A run that stops: the same keys, "error" and "stopped_at_s" among them.
    scenario.limits.max_modal_error = 0.05
    cli = simulate_with_the_cli(scenario, "pd", tmp_path / "stopped")
    python = scenario.run("pd").summary
    assert {"error", "stopped_at_s"} <= python.keys() and python.keys() == cli.keys()
    assert python["error"] == cli["error"]


def test_scenarios_pickle():
    import pickle

    scenario = short_step()
    scenario.seed = 7
    clone = pickle.loads(pickle.dumps(scenario))
    assert clone.to_dict() == scenario.to_dict()


def test_a_deployment_that_stops_returns_its_data_up_to_the_stop():
    """`Scenario.run_deploy` of a run that stops on a runaway joint: the data up to the stop,
    its summary with "error" and "stopped_at_s" (the last recorded time), as Scenario.run."""
    scenario = hrm.Scenario.builtin("pipe-deploy")
    scenario.duration = 0.5
    # Computed torque tracks the plan to 7e-8 over the 0.5 s: past 3e-8 at t = 0.025 s.
    scenario.limits.max_modal_error = 3e-8
    stopped = scenario.run_deploy()
    summary = stopped["summary"]
    assert "runaway tracking error" in summary["error"]
    k = len(stopped["t"])
    assert 1 < k < 10 and summary["stopped_at_s"] == stopped["t"][-1] < 0.025
    assert stopped["q"].shape == (k, scenario.arm.links + 1)
    assert stopped["points"].shape == (k, scenario.arm.links + 1, 2)
    assert math.isfinite(summary["deploy_tip_error_m"])


def test_pipe_deploy_runs_with_mpc_within_joint_torque_nm():
    """`Scenario.run_deploy`: pipe-deploy with the joint-space MPC, 0.3 s of it, within a joint
    torque limit set from Python; the arrays checked against each other and the arm."""
    scenario = hrm.Scenario.builtin("pipe-deploy")
    scenario.controller.kind = "mpc"
    scenario.duration = 0.3
    free = scenario.run_deploy()
    n = scenario.arm.links
    k = len(free["t"])
    assert free["q"].shape == free["q_ref"].shape == free["tau"].shape == (k, n + 1)
    assert free["points"].shape == (k, n + 1, 2)
    summary = free["summary"]
    assert summary["controller"] == "mpc" and summary["joints"] == n + 1
    # Every link of the drawn arm has the arm's link length.
    lengths = np.linalg.norm(np.diff(free["points"], axis=1), axis=2)
    assert np.allclose(lengths, scenario.arm.link_length, atol=1e-12)
    # The summary's final error and peaks from the time series.
    assert math.isclose(
        summary["final_error"],
        float(np.linalg.norm(free["q"][-1] - free["q_ref"][-1])),
        rel_tol=1e-12,
        abs_tol=1e-15,
    )
    peaks = np.array(summary["peak_joint_efforts"])
    assert np.all(peaks >= np.abs(free["tau"]).max(axis=0) - 1e-12)
    for key in (
        "deploy_tip_error_m",
        "deploy_shape_deviation_pct",
        "deploy_min_wall_clearance_m",
        "deploy_min_self_clearance_m",
    ):
        assert math.isfinite(summary[key]) and key in summary["plan"]
    # The body never lies over itself: links sharing no joint stay a link's width apart at least.
    assert summary["deploy_min_self_clearance_m"] > 0.05
    # Within [limits] joint_torque_nm, 60% of the free run's largest joint torque: every revolute
    # joint's torque within it at every controller sample (the summary's peaks).
    limit = 0.6 * float(peaks[1:].max())
    scenario.limits.joint_torque_nm = limit
    limited = scenario.run_deploy()
    assert max(limited["summary"]["peak_joint_efforts"][1:]) <= limit * (1 + 1e-12)
    assert np.abs(limited["tau"][:, 1:]).max() <= limit * (1 + 1e-12)
    # Keys a deployment does not use are refused by name.
    scenario.controller.kind = "computed-torque"
    with pytest.raises(hrm.InvalidInput, match="limits.joint_torque_nm"):
        scenario.run_deploy()
    with pytest.raises(hrm.InvalidInput, match="deploy"):
        hrm.Scenario.builtin("paper-tracking").run_deploy()


def test_a_run_the_viewer_cannot_draw_still_returns_its_data():
    # 1,200 links are more than the viewer draws (1,000): the run and its summary stand, the page
    # says why it is missing, and a pickled copy says the same.
    scenario = hrm.Scenario.builtin("paper-tracking")
    scenario.arm.links = 1200
    scenario.arm.link_length = 1.0 / 1200
    scenario.arm.link_mass = 1.0 / 1200
    scenario.duration = 0.01
    scenario.controller.kind = "pd"
    run = scenario.run()
    assert run.failure is None and run.t.shape[0] > 1 and run.summary["recorded_samples"] > 1
    with pytest.raises(hrm.InvalidInput, match="the viewer cannot draw the run"):
        run.view_html()
    assert run._repr_html_() is None
    with pytest.raises(hrm.InvalidInput, match="the viewer cannot draw the run"):
        pickle.loads(pickle.dumps(run)).view_html()


def test_nested_runs_are_bounded_and_do_not_wait_on_the_pool():
    # A controller that runs its own scenario again crashed the interpreter (Rust stack that
    # Python's recursion limit does not count): a RecursionError after 16 nested runs.
    scenario = hrm.Scenario.builtin("paper-tracking")
    scenario.duration = 0.001
    depth = [0]

    def again(t, a, a_dot, reference):
        depth[0] += 1
        scenario.run(again)
        return np.zeros(2)

    with pytest.raises(RecursionError, match="^runs nested more than 16 deep"):
        scenario.run(again)
    assert depth[0] == 16

    # Built-in runs nested three deep through disturbances waited forever for the pool's workers
    # on two cores: a run started on a worker runs there.
    returned = []

    def nest(level):
        started = [False]

        def disturbance(t, a, a_dot):
            if level < 3 and not started[0]:
                started[0] = True
                scenario.copy().run("pd", disturbance=nest(level + 1))
                returned.append(level)
            return None

        return disturbance

    run = scenario.run("pd", disturbance=nest(0))
    assert run.failure is None and returned == [2, 1, 0]
