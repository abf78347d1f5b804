"""hrm's spatial chains from URDF against Pinocchio (same URDF) and MuJoCo (hrm's MJCF): mass
matrix, C + G, ABA, the RNEA and ABA derivatives and link poses to 1e-9 relative, on random
chains (random axes, origins, inertias, some prismatic joints, a fixed tool link, 1 to 30
joints) and a 10-link universal-joint snake; the paper's arm exported as URDF gives in Pinocchio
(gravity along -y) the planar `dynamics`. Degenerate inertias (rods, spheres, plates) turned by
random rotations read as Pinocchio reads them and export as MuJoCo loads them; what MuJoCo
refuses (masses and moments below mjMINVAL) the export refuses; a root link `world` is MuJoCo's
world body. Drives `hrm eval` (JSON lines)."""

import json
import os
import pathlib
import subprocess

import numpy as np
import pytest

from engines import require
ROOT = pathlib.Path(__file__).resolve().parents[3]

try:
    import pinocchio as pin
except ImportError:
    pin = None
try:
    import mujoco
except ImportError:
    mujoco = None

TOL = 1e-9
GRAVITY = [0.0, 0.0, -9.81]


def hrm_binary():
    """`hrm` from $CARGO_TARGET_DIR or the workspace's target folder (debug or release)."""
    roots = [pathlib.Path(os.environ["CARGO_TARGET_DIR"])] if "CARGO_TARGET_DIR" in os.environ else []
    for root in roots + [ROOT / "target"]:
        for profile in ("debug", "release"):
            if (root / profile / "hrm").is_file():
                return root / profile / "hrm"
    pytest.skip("the hrm binary is not built (cargo build -p hrm-cli)")


def hrm_answers(requests):
    """Answers of `hrm eval` to a list of requests."""
    text = "".join(json.dumps(r) + "\n" for r in requests)
    out = subprocess.run([hrm_binary(), "eval"], input=text, capture_output=True, text=True, check=True)
    return [json.loads(line) for line in out.stdout.splitlines()]


def hrm_eval(requests):
    """Answers of `hrm eval` to a list of requests, each checked ok."""
    answers = hrm_answers(requests)
    for answer in answers:
        assert answer["ok"], answer
    return answers


def close(a, b, what):
    a, b = np.asarray(a, float), np.asarray(b, float)
    scale = max(1.0, np.abs(b).max())
    err = np.abs(a - b).max() / scale
    assert err <= TOL, f"{what}: relative difference {err:.3e}"
    return err


def random_chain(seed, n, massless_middles=False):
    """A URDF chain of n movable joints and a fixed tool link."""
    rng = np.random.default_rng(seed)
    f = lambda v: " ".join(repr(float(x)) for x in v)
    parts = ['<robot name="random">', '<link name="l0"/>']
    for i in range(1, n + 1):
        kind = "prismatic" if rng.random() < 0.25 else "revolute"
        parts.append(
            f'<joint name="j{i}" type="{kind}"><parent link="l{i-1}"/><child link="l{i}"/>'
            f'<origin xyz="{f(rng.uniform(-0.3, 0.3, 3))}" rpy="{f(rng.uniform(-3, 3, 3))}"/>'
            f'<axis xyz="{f(rng.normal(size=3))}"/><limit lower="-1" upper="1" effort="5" velocity="2"/></joint>')
        moments = [float(x) for x in rng.uniform(0.01, 0.1, 3)]
        moments[2] = float(rng.uniform(abs(moments[0] - moments[1]) + 1e-3, moments[0] + moments[1] - 1e-3))
        ixy = 0.0  # the rpy of <inertial> turns the principal axes
        parts.append(
            f'<link name="l{i}"><inertial><origin xyz="{f(rng.uniform(-0.2, 0.2, 3))}" rpy="{f(rng.uniform(-3, 3, 3))}"/>'
            f'<mass value="{float(rng.uniform(0.1, 2.0))!r}"/><inertia ixx="{moments[0]!r}" ixy="{ixy!r}" ixz="0" '
            f'iyy="{moments[1]!r}" iyz="0" izz="{moments[2]!r}"/></inertial></link>')
    parts.append(f'<joint name="tool_mount" type="fixed"><parent link="l{n}"/><child link="tool"/>'
                 '<origin xyz="0.1 0.02 0" rpy="0.3 0 0.2"/></joint>'
                 '<link name="tool"><inertial><origin xyz="0.01 0 0"/><mass value="0.3"/>'
                 '<inertia ixx="0.001" ixy="0.0001" ixz="0" iyy="0.002" iyz="0" izz="0.002"/></inertial></link></robot>')
    return "\n".join(parts)


def snake(links=10, middle_mass=0.05):
    """A universal-joint snake: per link a yaw joint, a small cross (massless if middle_mass is
    0) and a pitch joint carrying a 0.1 m tube."""
    parts = ['<robot name="snake">', '<link name="base"/>']
    parent = "base"
    for k in range(1, links + 1):
        x = 0.0 if k == 1 else 0.1
        cross = (f'<inertial><mass value="{middle_mass}"/><inertia ixx="1e-5" ixy="0" ixz="0" iyy="1e-5" iyz="0" izz="1e-5"/></inertial>'
                 if middle_mass > 0 else "")
        parts += [
            f'<joint name="yaw{k}" type="revolute"><parent link="{parent}"/><child link="cross{k}"/>'
            f'<origin xyz="{x} 0 0"/><axis xyz="0 0 1"/><limit lower="-2" upper="2" effort="5" velocity="3"/></joint>',
            f'<link name="cross{k}">{cross}</link>',
            f'<joint name="pitch{k}" type="revolute"><parent link="cross{k}"/><child link="tube{k}"/>'
            f'<axis xyz="0 1 0"/><limit lower="-2" upper="2" effort="5" velocity="3"/></joint>',
            f'<link name="tube{k}"><inertial><origin xyz="0.05 0 0"/><mass value="0.1"/>'
            f'<inertia ixx="2e-5" ixy="0" ixz="0" iyy="9.333e-5" iyz="0" izz="9.333e-5"/></inertial></link>',
        ]
        parent = f"tube{k}"
    parts.append("</robot>")
    return "\n".join(parts)


def pin_model(urdf, gravity):
    model = pin.buildModelFromXML(urdf)
    model.gravity.linear = np.array(gravity)
    return model, model.createData()


def pin_q(model, theta):
    """Pinocchio's configuration of joint values (continuous joints take cos and sin)."""
    q = []
    for joint, value in zip(list(model.joints)[1:], theta):
        q += [np.cos(value), np.sin(value)] if joint.nq == 2 else [value]
    return np.array(q)


def symmetric(upper):
    return np.triu(upper) + np.triu(upper, 1).T


def compare_with_pinocchio(urdf, theta, v, a, tau, gravity=GRAVITY):
    """Every quantity of hrm against Pinocchio; returns the largest relative difference."""
    model, data = pin_model(urdf, gravity)
    q = pin_q(model, theta)
    base = {"urdf": urdf, "gravity": gravity}
    dyn, rnea, aba, frames = hrm_eval([
        {"op": "dynamics", **base, "theta": list(theta), "theta_dot": list(v)},
        {"op": "rnea_derivatives", **base, "theta": list(theta), "theta_dot": list(v), "theta_ddot": list(a)},
        {"op": "aba_derivatives", **base, "theta": list(theta), "theta_dot": list(v), "tau": list(tau)},
        {"op": "frames", "urdf": urdf, "theta": list(theta)},
    ])
    errs = [close(dyn["mass_matrix"], symmetric(pin.crba(model, data, q)), "M")]
    errs.append(close(np.add(dyn["coriolis"], dyn["gravity"]), pin.nonLinearEffects(model, data, q, v), "C + G"))
    errs.append(close(dyn["gravity"], pin.computeGeneralizedGravity(model, data, q), "G"))
    pin.computeRNEADerivatives(model, data, q, v, a)
    errs.append(close(rnea["tau"], pin.rnea(model, data, q, v, a), "RNEA"))
    errs.append(close(rnea["d_theta"], data.dtau_dq, "d tau / d q"))
    errs.append(close(rnea["d_theta_dot"], data.dtau_dv, "d tau / d v"))
    pin.computeABADerivatives(model, data, q, v, tau)
    errs.append(close(aba["theta_ddot"], pin.aba(model, data, q, v, tau), "ABA"))
    errs.append(close(aba["d_theta"], data.ddq_dq, "d qdd / d q"))
    errs.append(close(aba["d_theta_dot"], data.ddq_dv, "d qdd / d v"))
    errs.append(close(aba["d_tau"], symmetric(data.Minv), "M^-1"))
    pin.forwardKinematics(model, data, q)
    errs.append(close(frames["positions"], [data.oMi[i].translation for i in range(1, model.njoints)], "positions"))
    errs.append(close(frames["rotations"], [data.oMi[i].rotation for i in range(1, model.njoints)], "rotations"))
    return max(errs)


def compare_with_mujoco(urdf, theta, v, gravity=GRAVITY, hrm_answer=None):
    """mj_fullM and qfrc_bias on hrm's MJCF against hrm's M and C + G (or Pinocchio's, given)."""
    (export,) = hrm_eval([{"op": "export", "urdf": urdf, "format": "mjcf", "gravity": gravity}])
    mj = mujoco.MjModel.from_xml_string(export["text"])
    d = mujoco.MjData(mj)
    d.qpos[:] = theta
    d.qvel[:] = v
    mujoco.mj_forward(mj, d)
    full = np.zeros((mj.nv, mj.nv))
    mujoco.mj_fullM(mj, d, full)
    if hrm_answer is None:
        (hrm_answer,) = hrm_eval([{"op": "dynamics", "urdf": urdf, "gravity": gravity,
                                   "theta": list(theta), "theta_dot": list(v)}])
        hrm_answer = (hrm_answer["mass_matrix"], np.add(hrm_answer["coriolis"], hrm_answer["gravity"]))
    m, bias = hrm_answer
    return max(close(full, m, "mj_fullM"), close(d.qfrc_bias, bias, "qfrc_bias"))


def states(n, seed):
    rng = np.random.default_rng(1000 + seed)
    return [rng.uniform(-1, 1, n) for _ in range(4)]


@pytest.mark.parametrize("seed", range(12))
def test_random_chains_agree_with_pinocchio_and_mujoco(seed):
    require(pin is not None, "Pinocchio (pin)")
    n = [1, 2, 3, 5, 7, 10, 13, 17, 20, 24, 27, 30][seed]
    urdf = random_chain(seed, n)
    theta, v, a, tau = states(n, seed)
    compare_with_pinocchio(urdf, theta, v, a, tau)
    require(mujoco is not None, "MuJoCo (mujoco)")
    compare_with_mujoco(urdf, theta, v)


def test_a_universal_joint_snake_agrees_with_pinocchio_and_mujoco():
    require(pin is not None, "Pinocchio (pin)")
    urdf = snake()
    theta, v, a, tau = states(20, 99)
    compare_with_pinocchio(urdf, theta, v, a, tau)
    require(mujoco is not None, "MuJoCo (mujoco)")
    compare_with_mujoco(urdf, theta, v)


def test_massless_crosses_agree_with_pinocchio_and_are_two_hinges_in_one_mujoco_body():
    """Massless crosses (a universal joint as URDF writes it): hrm agrees with Pinocchio on every
    quantity (ABA and its derivatives through the articulated inertias of massless bodies), and
    MuJoCo, on hrm's MJCF (two hinges in one body), with both."""
    require(pin is not None, "Pinocchio (pin)")
    urdf = snake(middle_mass=0.0)
    theta, v, a, tau = states(20, 7)
    compare_with_pinocchio(urdf, theta, v, a, tau)
    require(mujoco is not None, "MuJoCo (mujoco)")
    compare_with_mujoco(urdf, theta, v)
    (export,) = hrm_eval([{"op": "export", "urdf": urdf, "format": "mjcf"}])
    assert mujoco.MjModel.from_xml_string(export["text"]).nbody == 1 + 1 + 10


def test_the_paper_arm_as_urdf_in_pinocchio_gives_the_planar_dynamics():
    require(pin is not None, "Pinocchio (pin)")
    arm = {"links": 10, "link_length": 0.1, "link_mass": 0.1, "gravity": 9.81}
    (export,) = hrm_eval([{"op": "export", "arm": arm, "format": "urdf"}])
    rng = np.random.default_rng(5)
    theta, v = rng.uniform(-1, 1, 10), rng.uniform(-1, 1, 10)
    (planar,) = hrm_eval([{"op": "dynamics", "arm": arm, "theta": list(theta), "theta_dot": list(v)}])
    model, data = pin_model(export["text"], [0.0, -9.81, 0.0])
    q = pin_q(model, theta)
    close(symmetric(pin.crba(model, data, q)), planar["mass_matrix"], "M")
    close(pin.nonLinearEffects(model, data, q, v), np.add(planar["coriolis"], planar["gravity"]), "C + G")
    if mujoco is not None:
        (mjcf,) = hrm_eval([{"op": "export", "arm": arm, "format": "mjcf"}])
        mj = mujoco.MjModel.from_xml_string(mjcf["text"])
        assert list(mj.opt.gravity) == [0.0, -9.81, 0.0]


def one_link(inertial, root="b", extra=""):
    """A chain of one continuous joint about z from `root` to link 'a', whose <inertial> holds
    `inertial`; `extra` links and joints are added."""
    return (f'<robot name="r"><link name="{root}"/><link name="a"><inertial>{inertial}</inertial></link>'
            f'<joint name="j" type="continuous"><parent link="{root}"/><child link="a"/>'
            f'<axis xyz="0 1 0"/></joint>{extra}</robot>')


def inertial(tensor, rpy=(0.0, 0.0, 0.0), mass=1.0):
    """An <inertial> of `mass` at (0.1, 0.05, 0) in a frame turned by `rpy`, the tensor's six
    entries written exactly (repr)."""
    t = [[repr(float(x)) for x in row] for row in np.asarray(tensor, float)]
    r = " ".join(repr(float(x)) for x in rpy)
    return (f'<origin xyz="0.1 0.05 0" rpy="{r}"/><mass value="{float(mass)!r}"/>'
            f'<inertia ixx="{t[0][0]}" ixy="{t[0][1]}" ixz="{t[0][2]}" iyy="{t[1][1]}" '
            f'iyz="{t[1][2]}" izz="{t[2][2]}"/>')


def turned(moments, rng):
    """diag(moments) turned by a random rotation."""
    q = np.linalg.qr(rng.normal(size=(3, 3)))[0]
    return q @ np.diag(moments) @ q.T


def degenerate_inertias(seed, axial):
    """Rods (axial moment `axial` times I), spheres and thin plates, turned at random, and the
    thin plate of a turned <inertial> frame that MuJoCo refused as a rotated fullinertia."""
    rng = np.random.default_rng(seed)
    cases = [inertial(np.diag([0.01, 0.01, 0.02]), rpy=(0.3, 0.4, 0.5))]
    for _ in range(4):
        i, a, b = rng.uniform(0.01, 1.0, 3)
        for moments in ([axial * i, i, i], [i, i, i], [a, b, a + b]):
            cases.append(inertial(turned(moments, rng), rpy=rng.uniform(-3, 3, 3)))
            cases.append(inertial(turned(moments, rng)))
    return cases


def test_turned_slender_rods_read_as_pinocchio_reads_them():
    """Rods (0, I, I), exactly singular, turned at random or along (3, 4, 5): hrm reads them
    (the closed form of the cubic refused about 70%) and agrees with Pinocchio."""
    require(pin is not None, "Pinocchio (pin)")
    rods = degenerate_inertias(3, axial=0.0) + [
        inertial([[0.82, -0.24, -0.3], [-0.24, 0.68, -0.4], [-0.3, -0.4, 0.5]]),
        inertial(np.diag([0.0, 0.01, 0.01]), rpy=(0.0, 1.5707963267948966, 0.0)),
    ]
    for k, rod in enumerate(rods):
        theta, v, a, tau = states(1, k)
        compare_with_pinocchio(one_link(rod), theta, v, a, tau)


def test_degenerate_inertias_export_as_mujoco_loads_them():
    """Near-rods, spheres and plates turned by the <inertial> frame and as full tensors: the
    MJCF loads (MuJoCo checks A + B >= C exactly, and refused the rounding of a turned
    fullinertia), its diaginertia is MuJoCo's body_inertia, and mj_fullM and qfrc_bias agree with
    hrm and Pinocchio."""
    require(pin is not None and mujoco is not None, "Pinocchio (pin) and MuJoCo (mujoco)")
    for k, case in enumerate(degenerate_inertias(4, axial=1e-3)):
        urdf = one_link(case)
        theta, v, a, tau = states(1, k)
        compare_with_pinocchio(urdf, theta, v, a, tau)
        compare_with_mujoco(urdf, theta, v)
        (export,) = hrm_eval([{"op": "export", "urdf": urdf, "format": "mjcf"}])
        line = next(l for l in export["text"].splitlines() if "<inertial " in l)
        diagonal = [float(x) for x in line.split('diaginertia="')[1].split('"')[0].split()]
        assert list(mujoco.MjModel.from_xml_string(export["text"]).body_inertia[-1]) == diagonal


def test_what_mujoco_refuses_the_export_refuses_naming_the_link():
    """MuJoCo refuses a moving body's mass or principal moment below mjMINVAL = 1e-15, zero
    included (a slender rod's moment about its axis), and loads 1e-15: hrm's export refuses the
    same, in one line naming the link."""
    require(mujoco is not None, "MuJoCo (mujoco)")

    def body(inertial_attributes):
        return ('<mujoco><compiler inertiafromgeom="false"/><worldbody><body name="a">'
                f'<joint type="hinge"/><inertial pos="0 0 0" {inertial_attributes}/></body></worldbody></mujoco>')

    for attributes in ('mass="1" diaginertia="0 0.01 0.01"', 'mass="1" diaginertia="1e-16 1 1"',
                       'mass="1e-16" diaginertia="1 1 1"'):
        with pytest.raises(ValueError, match="mjMINVAL"):
            mujoco.MjModel.from_xml_string(body(attributes))
    for attributes in ('mass="1" diaginertia="1e-15 1 1"', 'mass="1e-15" diaginertia="1 1 1"'):
        mujoco.MjModel.from_xml_string(body(attributes))
    refused = [
        inertial(np.diag([1e-16, 1e-16, 1e-16]), mass=1e-16),
        inertial(np.diag([1e-300, 1.0, 1.0])),
        inertial(np.diag([0.0, 0.01, 0.01]), rpy=(0.0, 1.5707963267948966, 0.0)),
        inertial([[0.82, -0.24, -0.3], [-0.24, 0.68, -0.4], [-0.3, -0.4, 0.5]]),
    ]
    answers = hrm_answers([{"op": "export", "urdf": one_link(case), "format": "mjcf"} for case in refused])
    for answer in answers:
        assert not answer["ok"], answer
        message = answer["error"]["message"]
        assert "link 'a' to MJCF" in message and "at least 1e-15" in message, message


def test_a_root_link_named_world_is_mujocos_world_body():
    """ROS's root link `world`: MuJoCo refuses a body of that name, so it is the <worldbody>
    itself, the chain attached there; the dynamics agree with hrm and Pinocchio."""
    require(pin is not None and mujoco is not None, "Pinocchio (pin) and MuJoCo (mujoco)")
    urdf = one_link(inertial(np.diag([0.1, 0.2, 0.25])), root="world")
    theta, v, a, tau = states(1, 0)
    compare_with_pinocchio(urdf, theta, v, a, tau)
    compare_with_mujoco(urdf, theta, v)
    (export,) = hrm_eval([{"op": "export", "urdf": urdf, "format": "mjcf"}])
    mj = mujoco.MjModel.from_xml_string(export["text"])
    assert [mj.body(i).name for i in range(mj.nbody)] == ["world", "a"]


def test_a_massless_links_geometry_is_named_and_the_export_loads():
    """The visual and collision shapes of a massless link whose joint moves the next body are
    named in a comment (as geoms of that body they would move with its later joints); MuJoCo
    loads the file, the two hinges in one body."""
    require(mujoco is not None, "MuJoCo (mujoco)")
    sphere = '<origin xyz="0.3 0 0"/><geometry><sphere radius="0.05"/></geometry>'
    for element in ("visual", "collision"):
        urdf = (f'<robot name="r"><link name="b"/><link name="m"><{element}>{sphere}</{element}></link>'
                f'<link name="a"><inertial>{inertial(np.diag([0.1, 0.1, 0.1]))}</inertial></link>'
                '<joint name="j1" type="continuous"><parent link="b"/><child link="m"/><axis xyz="0 0 1"/></joint>'
                '<joint name="j2" type="continuous"><parent link="m"/><child link="a"/><origin xyz="0.2 0 0"/>'
                '<axis xyz="0 0 1"/></joint></robot>')
        (export,) = hrm_eval([{"op": "export", "urdf": urdf, "format": "mjcf"}])
        assert "<!-- link 'm' (massless, its joint moves this body) has" in export["text"]
        mj = mujoco.MjModel.from_xml_string(export["text"])
        assert (mj.nbody, mj.njnt, mj.ngeom) == (3, 2, 0)


def largest_differences():
    """The table of docs/robot-descriptions.md: python -c 'import test_robot_engines as t; t.largest_differences()'."""
    rows = []
    for seed in range(12):
        n = [1, 2, 3, 5, 7, 10, 13, 17, 20, 24, 27, 30][seed]
        urdf = random_chain(seed, n)
        theta, v, a, tau = states(n, seed)
        rows.append((f"random, {n} joints", compare_with_pinocchio(urdf, theta, v, a, tau),
                     compare_with_mujoco(urdf, theta, v)))
    urdf = snake()
    theta, v, a, tau = states(20, 99)
    rows.append(("snake, 20 joints", compare_with_pinocchio(urdf, theta, v, a, tau), compare_with_mujoco(urdf, theta, v)))
    for name, p, m in rows:
        print(f"| {name} | {p:.1e} | {m:.1e} |")
