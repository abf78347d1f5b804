"""Scenarios on spatial modal arms from Python: the shipped spatial-tracking run with its 3-D
tips, a spatial scenario file, Python controllers and disturbances of 2n joints, the refusals
of the spatial keys, and a sweep."""

import math

import numpy as np
import pytest

import hrm


def short_spatial(duration=0.3):
    scenario = hrm.Scenario.builtin("spatial-tracking")
    scenario.duration = duration
    return scenario


def test_spatial_tracking_runs_with_tips_in_space():
    scenario = short_spatial()
    assert scenario.n_coords == 4
    assert scenario.coordinate_names == ["az1", "az2", "ay1", "ay2"]
    run = scenario.run("computed-torque")
    k = len(run.t)
    assert run.failure is None and run.coordinates == ["az1", "az2", "ay1", "ay2"]
    for name, width in [("a", 4), ("tau_star", 4), ("joint_torques", 20), ("tip", 3), ("tip_ref", 3)]:
        assert getattr(run, name).shape == (k, width), name
    # The reference tip runs on the circle of radius 0.15 m about the x axis at x = 0.8 m.
    ref = run.tip_ref
    np.testing.assert_allclose(ref[:, 0], 0.8, atol=1e-9)
    np.testing.assert_allclose(np.hypot(ref[:, 1], ref[:, 2]), 0.15, atol=1e-9)
    assert ref[:, 2].max() > 0.05
    # The summary's tip error is the distance in space.
    error = np.linalg.norm(run.tip - run.tip_ref, axis=1)
    assert math.isclose(run.summary["tip_error_rms_m"], np.sqrt(np.mean(error**2)), rel_tol=1e-12)
    assert run.summary["tip_error_rms_m"] < 1e-3


def test_a_spatial_scenario_file_with_a_python_controller_and_disturbance(tmp_path):
    path = tmp_path / "spatial.toml"
    path.write_text(
        'name = "spatial-hold"\nduration = 0.2\n'
        '[arm]\nkind = "spatial"\njoints = "universal"\nlinks = 6\nlink_length = 0.1\nlink_mass = 0.1\n'
        "gravity = [0.0, 0.0, -9.81]\ninertias = " + str([[1e-6, 1e-4, 1e-4]] * 6) + "\n"
        "[arm.base]\nxyz = [0.0, 0.0, 0.5]\nrpy = [0.0, 0.0, 0.3]\n"
        '[reference]\nkind = "step"\ntarget = [0.1, 0.0, -0.1, 0.05]\ntime = 0.05\n'
        # PD gains for these light links: the fuzzy slope's (kd 20 and 10) run away at a 1 ms sample.
        '[controller]\nkind = "computed-torque"\npd_kp = [10.0, 10.0, 10.0, 10.0]\npd_kd = [1.0, 1.0, 1.0, 1.0]\n'
        '[integrator]\nmethod = "rk4"\ndt = 0.001\n'
    )
    scenario = hrm.Scenario.from_toml(path)
    assert scenario.arm.kind == "spatial" and scenario.arm.gravity == [0.0, 0.0, -9.81]
    builtin = scenario.run("computed-torque")
    assert builtin.failure is None and builtin.joint_torques.shape[1] == 12
    # The tip of the arm at rest leaves the base at (0, 0, 0.5) along its yaw of 0.3 rad.
    start = builtin.tip[0]
    assert math.isclose(start[2], 0.5, abs_tol=1e-12)
    assert math.isclose(math.atan2(start[1], start[0]), 0.3, abs_tol=1e-12)
    seen = []

    # Gains of a loop sampled every 1 ms that stays stable on these light links (M*_ii of order
    # 1e-3 kg m^2: a rate gain of 10 would make kd dt / M* about 10, a runaway in 0.1 s).
    def hold(t, a, a_dot, ref):
        return -10.0 * (a - ref.a) - 1.0 * a_dot

    def push(t, a, a_dot):
        seen.append(t)
        return np.full(12, 0.01)

    pushed = scenario.run(hold, disturbance=push)
    assert pushed.failure is None and len(seen) == pushed.summary["controller_samples"]
    assert not np.allclose(pushed.a, scenario.run(hold).a)
    for name in ["fuzzy", "pd", "fuzzy-gc", "lqr"]:
        assert scenario.run(name).failure is None, name


def test_spatial_keys_are_checked_with_the_library_messages():
    scenario = short_spatial()
    scenario.arm.inertias = [[1.0, 1e-4, 1e-4]] * 10
    with pytest.raises(hrm.InvalidInput, match=r"^arm.inertias\[0\] is invalid"):
        scenario.run("computed-torque")
    scenario = short_spatial()
    scenario.alpha0 = 1.0
    with pytest.raises(hrm.InvalidInput, match="^alpha0 is not used with a spatial arm"):
        scenario.run("computed-torque")
    scenario = short_spatial()
    scenario.modal.harmonics = 6
    with pytest.raises(hrm.InvalidInput, match="^modal.harmonics = 6"):
        scenario.run("computed-torque")


def test_a_sweep_of_a_spatial_scenario():
    sweep = hrm.Sweep(short_spatial(0.1), noise_levels=[0.0, 1e-3], seeds=2, controllers=["computed-torque"])
    result = sweep.run()
    cells = result["cells"]
    assert [c["noise_level"] for c in cells] == [0.0, 1e-3]
    assert all(c["runs"] == 2 and c["failed"] == 0 for c in cells)


def test_spatial_clutter_by_name_is_planned_and_reaches_its_target_among_the_obstacles():
    assert "spatial-clutter" in hrm.Scenario.builtin_names()
    scenario = hrm.Scenario.builtin("spatial-clutter")
    assert scenario.arm.kind == "spatial" and scenario.n_coords == 4
    target = np.array(scenario.task.target)
    assert target.shape == (3,)
    run = scenario.run("computed-torque")
    assert run.failure is None
    # The tip ends on the target and holds it over the last half second.
    hold = run.t >= scenario.duration - 0.5
    miss = np.linalg.norm(run.tip[hold] - target, axis=1)
    assert miss.max() < 3e-3, miss.max()
    # The loop's smallest clearance over every controller sample keeps most of the 1 cm margin.
    assert run.summary["min_clearance_m"] > 0.005, run.summary["min_clearance_m"]
    # A target of the plane is refused by name on this spatial arm.
    scenario.task.target = [0.5, 0.3]
    with pytest.raises(hrm.InvalidInput, match=r"^task.target must be a point \[x, y, z\], got 2 numbers"):
        scenario.run("computed-torque")
