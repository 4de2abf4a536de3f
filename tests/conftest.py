"""Shared fixtures and hypothesis strategies: random floating-base robots written as URDF."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import tempfile
import warnings
from pathlib import Path

import numpy as np
import pytest
from hypothesis import strategies as st

from freefloat import load_robot
from freefloat.inputs import toml_text  # noqa: F401  (the tests write scene files with it)


@pytest.fixture(autouse=True)
def pinocchio_seeded():
    """Pinocchio's own generator (``pin.randomConfiguration``, ``pin.SE3.Random``) seeded before
    every test, so a test that draws from it draws the same numbers in every run and order."""
    import pinocchio as pin

    pin.seed(0)


#: freefloat's on-disk cache of robot loads for this session (``FREEFLOAT_CACHE_DIR``), for the tests and the
#: commands they start, set before any test module is imported: never the user's own cache.
CACHE_DIR = tempfile.mkdtemp(prefix="freefloat-test-cache-")
os.environ["FREEFLOAT_CACHE_DIR"] = CACHE_DIR


def pytest_unconfigure(config):
    """The session's cache folder removed at its end."""
    shutil.rmtree(CACHE_DIR, ignore_errors=True)


REPO = Path(__file__).resolve().parents[1]
SPART = REPO / "tests" / "data" / "spart"  # SPART reference values, copied from shared/reference/spart


def random_urdf(rng: np.random.Generator, n_links: int, fixed_share: float = 0.2, aligned_share: float = 0.0,
                continuous_share: float = 0.0) -> str:
    """A random tree: each link hangs from a random earlier one by a revolute, prismatic or fixed
    joint with a random pose and axis; random masses, CoMs (rotated inertial frames) and
    positive-definite inertias (sums of point-mass-like terms, so the triangle inequality holds).
    ``aligned_share`` of the movable joints turn or slide along an axis of their frame, either sign
    (+-x, +-y, +-z), and ``continuous_share`` of the revolute ones are continuous (both zero: the
    trees of earlier versions, seed for seed)."""

    def inertial(mass: float) -> str:
        xyz = rng.uniform(-0.2, 0.2, 3)
        rpy = rng.uniform(-np.pi, np.pi, 3)
        a = rng.uniform(0.05, 0.5, 3)
        principal = mass / 12.0 * np.array([a[1]**2 + a[2]**2, a[0]**2 + a[2]**2, a[0]**2 + a[1]**2])
        return (f'<inertial><origin xyz="{xyz[0]:.17g} {xyz[1]:.17g} {xyz[2]:.17g}" rpy="{rpy[0]:.17g} {rpy[1]:.17g} {rpy[2]:.17g}"/>'
                f'<mass value="{mass:.17g}"/><inertia ixx="{principal[0]:.17g}" iyy="{principal[1]:.17g}" '
                f'izz="{principal[2]:.17g}" ixy="0" ixz="0" iyz="0"/></inertial>')

    parts = ['<robot name="random">', f'<link name="base">{inertial(rng.uniform(5.0, 50.0))}</link>']
    for i in range(1, n_links + 1):
        parent = "base" if (k := rng.integers(0, i)) == 0 else f"l{k}"
        kind = "fixed" if rng.random() < fixed_share else ("prismatic" if rng.random() < 0.2 else "revolute")
        axis = rng.normal(size=3)
        axis /= np.linalg.norm(axis)
        if aligned_share and rng.random() < aligned_share:
            axis = np.eye(3)[rng.integers(3)] * rng.choice([-1.0, 1.0])
        if kind == "revolute" and continuous_share and rng.random() < continuous_share:
            kind = "continuous"
        xyz = rng.uniform(-0.6, 0.6, 3)
        rpy = rng.uniform(-np.pi, np.pi, 3)
        limit = '<limit lower="-3" upper="3" effort="100" velocity="10"/>' if kind in ("revolute", "prismatic") else ""
        parts.append(f'<link name="l{i}">{inertial(rng.uniform(0.2, 5.0))}</link>')
        parts.append(
            f'<joint name="j{i}" type="{kind}"><parent link="{parent}"/><child link="l{i}"/>'
            f'<origin xyz="{xyz[0]:.17g} {xyz[1]:.17g} {xyz[2]:.17g}" rpy="{rpy[0]:.17g} {rpy[1]:.17g} {rpy[2]:.17g}"/>'
            f'<axis xyz="{axis[0]:.17g} {axis[1]:.17g} {axis[2]:.17g}"/>{limit}</joint>'
        )
    parts.append("</robot>")
    return "\n".join(parts)


@st.composite
def random_robots(draw, min_links: int = 1, max_links: int = 8):
    """(seed, URDF text) of a random floating-base tree with at least one movable joint."""
    seed = draw(st.integers(0, 2**32 - 1))
    n = draw(st.integers(min_links, max_links))
    rng = np.random.default_rng(seed)
    text = random_urdf(rng, n)
    while 'type="revolute"' not in text and 'type="prismatic"' not in text:
        text = random_urdf(rng, n)
    return seed, text


@st.composite
def random_trees(draw, min_links: int = 1, max_links: int = 8):
    """(seed, URDF text, base) of a random tree with at least one movable joint on a free, planar or
    fixed base: revolute, continuous, prismatic and fixed joints, on general axes and on axes of
    their frames."""
    seed = draw(st.integers(0, 2**32 - 1))
    n = draw(st.integers(min_links, max_links))
    base = draw(st.sampled_from(["free", "planar", "fixed"]))
    rng = np.random.default_rng(seed)
    text = random_urdf(rng, n, aligned_share=0.5, continuous_share=0.3)
    while 'type="revolute"' not in text and 'type="prismatic"' not in text and 'type="continuous"' not in text:
        text = random_urdf(rng, n, aligned_share=0.5, continuous_share=0.3)
    return seed, text, base


def load_text(tmp_path: Path, text: str, name: str = "robot.urdf", **kwargs):
    """Write URDF text to a file and load it, silencing loader notes."""
    path = tmp_path / name
    path.write_text(text)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return load_robot(path, **kwargs)


def robot_from_case(factory, case, **kwargs):
    """Load a drawn ``(seed, URDF text)`` case; return the robot and an RNG seeded with the case."""
    seed, text = case
    return load_text(factory.mktemp("r"), text, **kwargs), np.random.default_rng(seed)


def random_state(robot, rng: np.random.Generator, speed: float = 1.0):
    """A random configuration (unit base quaternion, unit (cos, sin) of continuous joints) and
    velocity for ``robot``."""
    import pinocchio as pin

    q = pin.neutral(robot.model)
    nbq = robot.model.nqs[1]
    q[nbq:] = rng.uniform(-1.0, 1.0, robot.model.nq - nbq)
    if robot.base == "free":
        q[:3] = rng.uniform(-1.0, 1.0, 3)
        quat = rng.normal(size=4)
        q[3:7] = quat / np.linalg.norm(quat)
    else:
        yaw = rng.uniform(-np.pi, np.pi)
        q[:4] = [*rng.uniform(-1, 1, 2), np.cos(yaw), np.sin(yaw)]
    return pin.normalize(robot.model, q), speed * rng.uniform(-1.0, 1.0, robot.model.nv)  # continuous joints: (cos, sin)


@pytest.fixture(scope="session")
def spart_dir() -> Path:
    """SPART reference folder (tests/data/spart): its URDFs and its values at one state each."""
    return SPART


def scene_variant(path: Path, builtin: str, **sections: dict) -> Path:
    """Write the built-in scene ``builtin`` to ``path`` (.toml) with the given keys of each
    section replaced (``simulation={"duration": 0.01}``; a mechanism's reaching phase is halved
    down to half the shortened run); returns the path."""
    import tomllib

    from freefloat.app.scenes import builtin_scenes

    raw = tomllib.loads(builtin_scenes()[builtin].read_text())
    for section, values in sections.items():
        raw.setdefault(section, {}).update(values)
    duration = raw.get("simulation", {}).get("duration")
    reaching = raw.get("metrics", {}).get("reaching_phase")
    if "metrics" not in sections and reaching is not None and duration is not None and reaching >= duration:
        raw["metrics"]["reaching_phase"] = duration / 2  # a shortened run still measures its tracking
    path.write_text(toml_text(raw))
    return path


#: The default task with arm 1 moving only, over 1 s: the controller holds arms 2-4 still.
ONE_ARM_TASK = {"displacement": {"arm1_ee": 5.0}, "duration": 1.0}


def quiet_scene(tmp_path: Path, builtin: str = "four_arm_joint_space", **sections: dict):
    """The built-in scene with the given keys replaced (see :func:`scene_variant`), without
    figures or page, loaded."""
    from freefloat.app.scenes import load_scene

    sections.setdefault("output", {"figures": False, "html": False})
    return load_scene(scene_variant(tmp_path / "s.toml", builtin, **sections))


#: Components of [P; L about the inertial origin] that no root-joint reaction changes: all six for
#: a free base; Px, Py, Lz for a planar base (its reactions are a z force and x, y torques).
CONSERVED = {"free": [0, 1, 2, 3, 4, 5], "planar": [0, 1, 5]}


def torque_free(base: str, seed: int, speed: float):
    """SPART's SC_3DoF on a ``base`` root (``"free"`` or ``"planar"``), torque-free, from a
    :func:`random_state`: ``(robot, f, q0, v0)`` with ``f(q, v) -> a`` (nv,) by Pinocchio's ABA."""
    from freefloat.dynamics.models import ExactModel

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        robot = load_robot(SPART / "urdf" / "SC_3DoF.urdf", base=base, visuals=False)
    model, tau = ExactModel(robot), np.zeros(robot.model.nv)
    q0, v0 = random_state(robot, np.random.default_rng(seed), speed)
    return robot, lambda q, v: model.acceleration(q, v, tau), q0, v0


#: ``python -m freefloat`` with Ctrl-C's default handler installed first (see :func:`cli_process`).
_FOREGROUND = ("import runpy, signal, sys; signal.signal(signal.SIGINT, signal.default_int_handler); "
               "sys.argv[0] = 'freefloat'; runpy.run_module('freefloat', run_name='__main__')")


def cli_process(*args: str) -> subprocess.Popen:
    """``python -u -m freefloat ARGS`` with pipes for stdout and stderr (text), as a terminal's
    foreground process: Ctrl-C (SIGINT) handled even when the tests run in the background with
    SIGINT ignored, which a child inherits (a background job rightly ignores Ctrl-C)."""
    return subprocess.Popen([sys.executable, "-u", "-c", _FOREGROUND, *args], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True)


def box_in_both_hands(seed: int):
    """The dual-arm satellite at a random posture with a 50 kg box whose two grasp points lie on
    its two tool frames, the box turned at random: ``(robot, body, q, q_t, rng)`` (q_t: the box's
    pose, xyz and quaternion)."""
    import pinocchio as pin

    from freefloat.space.capture import Target, TargetBody
    from freefloat.space.dual_capture import second_grasp_at_contact

    robot = load_robot(REPO / "urdf" / "dual_arm_satellite.urdf", visuals=False)
    rng = np.random.default_rng(seed)
    q = pin.neutral(robot.model)
    q[7:] = rng.uniform(-0.5, 0.5, robot.model.nq - 7)
    data = robot.model.createData()
    pin.framesForwardKinematics(robot.model, data, q)
    rotation = pin.exp3(rng.normal(size=3))
    grasp = np.array([-0.25, 0.3, 0.0])
    second = second_grasp_at_contact(robot, ("left_tool0", "right_tool0"), q, grasp, rotation)
    position = data.oMf[robot.model.getFrameId("left_tool0")].translation - rotation @ grasp
    target = Target(mass=50.0, inertia=(2.0, 2.5, 3.0), grasp=tuple(grasp), position=tuple(position),
                    rpy=tuple(pin.rpy.matrixToRpy(rotation)))
    return robot, TargetBody(target, (second,)), q, pin.SE3ToXYZQUAT(pin.SE3(rotation, position)), rng


def box_held_in_both_hands(seed: int):
    """:func:`box_in_both_hands` with the box held: ``(merged robot, its loop closure, q, a
    velocity the loop allows)`` (random, 0.2 rad/s or m/s in size, projected on the closure)."""
    from freefloat.dynamics.closures import kinematics, stacked
    from freefloat.space.dual_capture import attach_with_loop

    robot, body, q, q_t, rng = box_in_both_hands(seed)
    merged, closure = attach_with_loop(robot, ("left_tool0", "right_tool0"), q, body, q_t)
    data = merged.model.createData()
    kinematics(merged.model, data, q, np.zeros(merged.model.nv))
    J = stacked([closure], merged.model, data, drift=False)[1]
    v = rng.normal(size=merged.model.nv) * 0.2
    return merged, closure, q, v - np.linalg.pinv(J) @ (J @ v)


def leak_momentum(monkeypatch, torque: float = 1e-3) -> None:
    """Make every robot run's recorded momentum gain the angular impulse of a spurious ``torque``
    (N m) about z before its summary is taken, as if its plant applied a torque nothing in the
    scene accounts for (a conservation law broken on purpose)."""
    import dataclasses

    from freefloat.dynamics import metrics

    original = metrics.conservation

    def leaking(telemetry, *args, **kwargs):
        momentum = telemetry.momentum.copy()
        momentum[:, 5] += torque * (telemetry.t - telemetry.t[0])
        return original(dataclasses.replace(telemetry, momentum=momentum), *args, **kwargs)

    monkeypatch.setattr(metrics, "conservation", leaking)
