"""The paper's comparison (section 5) from Python: every controller on every paper scenario,
printed as a table, and Figure 10 (the arm's backbone on the tracking path) drawn with
matplotlib when it is installed.

Run: python examples/python/paper_comparison.py [figure10.png]
(without an argument the figure goes to the system's temporary folder). The same runs are the
main job of the `hrm` command (`hrm run`), whose comparison.txt this table matches.
"""

import os
import sys
import tempfile

import numpy as np

import hrm

SCENARIOS = ["paper-tracking", "paper-responses-step", "paper-responses-sine", "paper-responses-noise"]
CONTROLLERS = ["fuzzy", "pd", "computed-torque", "fuzzy-gc"]

runs = {}
header = f"{'scenario':<22} {'controller':<16} {'tip rms mm':>10} {'tip max mm':>10} {'modal rms (rad)':>20} " \
         f"{'peak tau N m':>12} {'effort':>11}"
print(header)
for name in SCENARIOS:
    scenario = hrm.Scenario.builtin(name)
    for controller in CONTROLLERS:
        run = scenario.run(controller)
        runs[name, controller] = run
        s = run.summary
        modal = ", ".join(f"{v:.2e}" for v in s["modal_error_rms_rad"])
        row = f"{name:<22} {controller:<16} {s['tip_error_rms_m'] * 1e3:>10.4f} {s['tip_error_max_m'] * 1e3:>10.4f} " \
              f"{modal:>20} {s['peak_joint_torque_nm']:>12.3f} {s['control_effort_n2m2s']:>11.4e}"
        print(row if run.failure is None else f"{row}  stopped: {run.failure}")

# The paper's headline figures (fuzzy control of the tracking task), pinned by the test suite.
fuzzy = runs["paper-tracking", "fuzzy"].summary
assert f"{fuzzy['tip_error_rms_m'] * 1e3:.4f} {fuzzy['tip_error_max_m'] * 1e3:.4f}" == "4.8313 6.6222", fuzzy


def backbone(model, lengths, a):
    """The chain's joint positions (x, y) for modal coordinates a: theta = J a + theta_0 (eq 7),
    each theta_i relative to the previous link."""
    absolute = np.cumsum(model.joint_angles(a))
    steps = lengths[:, None] * np.stack([np.cos(absolute), np.sin(absolute)], axis=1)
    return np.vstack([np.zeros(2), np.cumsum(steps, axis=0)])


try:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
except ImportError:
    print("matplotlib is not installed: Figure 10 not drawn (pip install matplotlib)")
    sys.exit(0)

scenario = hrm.Scenario.builtin("paper-tracking")
arm = hrm.Arm(links=scenario.arm.links, link_length=scenario.arm.link_length, link_mass=scenario.arm.link_mass)
model = hrm.ReducedModel(arm, alpha0=scenario.alpha0)
run = runs["paper-tracking", "fuzzy"]
figure, axes = plt.subplots(figsize=(6, 6))
axes.plot(*run.tip_ref.T, "k--", label="reference path (eq 25)")
axes.plot(*run.tip.T, "C3", label="tip")
times = np.arange(0.0, run.t[-1] + 1e-9, 0.5)
for k, t in enumerate(times):
    row = int(np.argmin(np.abs(run.t - t)))
    points = backbone(model, arm.lengths, run.a[row])
    assert np.allclose(points[-1], run.tip[row], atol=1e-12)
    shade = 0.8 - 0.7 * k / max(len(times) - 1, 1)
    axes.plot(*points.T, "-o", color=(shade, shade, shade), markersize=2)
axes.set_aspect("equal")
axes.set_xlabel("x (m)")
axes.set_ylabel("y (m)")
axes.set_title("paper-tracking, fuzzy controller: backbone every 0.5 s (Figure 10)")
axes.legend(loc="lower left")
out = sys.argv[1] if len(sys.argv) > 1 else os.path.join(tempfile.gettempdir(), "hrm-figure10.png")
figure.savefig(out, dpi=120)
print("Figure 10:", out)
