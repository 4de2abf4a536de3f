"""Reaction wheels on the base (freefloat.robot.wheels): an added wheel is the tree Pinocchio builds
from a URDF with that wheel; its momentum is Pinocchio's; the GJM of the robot with wheels is the
arm's GJM with the wheels' stored momentum as its momentum term (eqs 84-88); bad wheels are
refused naming the key."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from freefloat import RobotModelError, SceneError
from freefloat.app.experiments.joint_space import prepare
from freefloat.dynamics import gjm
from freefloat.robot.locking import lock_joints
from freefloat.robot.wheels import WheelSpec, mount_wheels

from .conftest import load_text, quiet_scene, random_robots, random_state, random_urdf

unit_vectors = st.lists(st.floats(-1.0, 1.0), min_size=3, max_size=3).filter(lambda a: np.linalg.norm(a) > 0.1)


def wheel_urdf(name: str, axis: np.ndarray, position: np.ndarray, mass: float, axial: float, transverse: float) -> str:
    """A rotor on a continuous joint of the root link, written directly in the URDF (Pinocchio
    builds its own joint about ``axis``, with the axisymmetric inertia spelled out)."""
    a = axis / np.linalg.norm(axis)
    inertia = transverse * (np.eye(3) - np.outer(a, a)) + axial * np.outer(a, a)
    entries = " ".join(f'{k}="{inertia[i, j]:.17g}"' for k, (i, j) in
                       zip(("ixx", "ixy", "ixz", "iyy", "iyz", "izz"), ((0, 0), (0, 1), (0, 2), (1, 1), (1, 2), (2, 2))))
    xyz = " ".join(f"{x:.17g}" for x in position)
    return (f'<link name="{name}_rotor"><inertial><mass value="{mass:.17g}"/><inertia {entries}/></inertial></link>'
            f'<joint name="{name}" type="continuous"><parent link="base"/><child link="{name}_rotor"/>'
            f'<origin xyz="{xyz}" rpy="0 0 0"/><axis xyz="{" ".join(f"{x:.17g}" for x in a)}"/></joint>')


def joint_maps(mine: pin.Model, theirs: pin.Model) -> tuple[np.ndarray, np.ndarray]:
    """Index maps ``(iq, iv)`` such that ``theirs`` coordinate k is ``mine``'s ``iq[k]`` / ``iv[k]``,
    matched by joint name."""
    iq, iv = np.zeros(theirs.nq, dtype=int), np.zeros(theirs.nv, dtype=int)
    for j in range(1, theirs.njoints):
        k = mine.getJointId(theirs.names[j])
        iq[theirs.idx_qs[j]:theirs.idx_qs[j] + theirs.nqs[j]] = range(mine.idx_qs[k], mine.idx_qs[k] + mine.nqs[k])
        iv[theirs.idx_vs[j]:theirs.idx_vs[j] + theirs.nvs[j]] = range(mine.idx_vs[k], mine.idx_vs[k] + mine.nvs[k])
    return iq, iv


@settings(max_examples=8, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), axis=unit_vectors, mass=st.floats(0.5, 5.0), axial=st.floats(0.01, 0.5),
       flat=st.floats(0.5, 1.5))
def test_an_added_wheel_is_the_tree_pinocchio_builds_from_its_urdf(tmp_path_factory, seed, axis, mass, axial, flat):
    """A wheel freefloat adds to a random robot gives the mass matrix and centroidal momentum of the
    robot Pinocchio parses from a URDF with that rotor on a continuous joint of the root link, at a
    random state (any wheel angle: the rotor is axisymmetric)."""
    rng = np.random.default_rng(seed)
    text = random_urdf(rng, 4, fixed_share=0.0)
    position = rng.uniform(-0.5, 0.5, 3)
    transverse = 0.5 * axial * flat + 0.5 * axial  # from half the axial moment (thin disc) up
    tmp = tmp_path_factory.mktemp("w")
    plain = load_text(tmp, text, "plain.urdf", visuals=False)
    spec = WheelSpec("wheel", max_momentum=1.0, max_torque=1.0, axis=tuple(axis), position=tuple(position),
                     mass=mass, inertia=axial, transverse_inertia=transverse)
    mine = mount_wheels(plain, [spec]).robot.model
    urdf_wheel = wheel_urdf("wheel", np.array(axis), position, mass, axial, transverse)
    parsed = load_text(tmp, text.replace("</robot>", urdf_wheel + "</robot>"), "wheel.urdf", visuals=False)
    theirs = parsed.model
    iq, iv = joint_maps(mine, theirs)
    q_t, v_t = random_state(parsed, rng)
    q_m, v_m = np.zeros(mine.nq), np.zeros(mine.nv)
    q_m[iq], v_m[iv] = q_t, v_t
    M_m = pin.crba(mine, mine.createData(), q_m)
    M_t = pin.crba(theirs, theirs.createData(), q_t)
    M_m, M_t = np.triu(M_m) + np.triu(M_m, 1).T, np.triu(M_t) + np.triu(M_t, 1).T
    assert np.allclose(M_m[np.ix_(iv, iv)], M_t, rtol=0.0, atol=1e-12 * np.abs(M_t).max())
    h_m = pin.computeCentroidalMomentum(mine, mine.createData(), q_m, v_m).vector
    h_t = pin.computeCentroidalMomentum(theirs, theirs.createData(), q_t, v_t).vector
    assert np.allclose(h_m, h_t, rtol=0.0, atol=1e-12 * max(1.0, np.abs(h_t).max()))


@settings(max_examples=8, deadline=None)
@given(case=random_robots(min_links=2, max_links=6), axes=st.lists(unit_vectors, min_size=1, max_size=3))
def test_the_gjm_with_wheels_is_the_arm_gjm_with_the_stored_momentum(tmp_path_factory, case, axes):
    """On a random robot with wheels, freefloat.gjm of the whole tree gives the end-effector
    velocities Pinocchio gives, and so does eq 88 of the arm alone (the wheels locked: a model
    Pinocchio reduces independently) with the momentum ``M - H0w Omega``; the wheels' columns of
    J* are ``-J0E H0^-1 H0w`` and their stored momentum ``[0; sum I Omega R a]`` about the base CoM."""
    seed, text = case
    rng = np.random.default_rng(seed)
    robot = load_text(tmp_path_factory.mktemp("g"), text, visuals=False)
    specs = [WheelSpec(f"w{i}", 1.0, 1.0, axis=tuple(a), position=tuple(rng.uniform(-0.3, 0.3, 3)), mass=1.0,
                       inertia=rng.uniform(0.01, 0.1)) for i, a in enumerate(axes)]
    wheels = mount_wheels(robot, specs)
    full = wheels.robot
    q, v = random_state(full, rng)
    state = gjm.compute(full, q, v)
    arm = lock_joints(full, [w.name for w in wheels.wheels], q)
    q_a, v_a = arm.reduce(q, v)
    arm_state = gjm.compute(arm.robot, q_a, v_a)
    omega = wheels.speeds(v)
    scale = max(1.0, np.abs(state.Jstar).max())
    assert np.allclose(arm_state.H0, state.H0, rtol=0.0, atol=1e-12 * np.abs(state.H0).max())
    assert np.allclose(arm_state.Jstar, state.Jstar[:, wheels.arm_columns], rtol=0.0, atol=1e-11 * scale)
    H0w = state.H0m[:, wheels.columns]
    assert np.allclose(state.Jstar[:, wheels.columns], -state.J0E @ np.linalg.solve(state.H0, H0w), atol=1e-11 * scale)
    rotation = pin.Quaternion(q[3:7]).toRotationMatrix()
    stored = np.concatenate((np.zeros(3), rotation @ wheels.axes() @ (wheels.inertias * omega)))
    assert np.allclose(state.momentum_base - arm_state.momentum_base, stored, rtol=0.0, atol=1e-12 * scale)
    model, data = full.model, full.model.createData()
    pin.forwardKinematics(model, data, q, v)
    pin.updateFramePlacements(model, data)
    truth = np.concatenate([pin.getFrameVelocity(model, data, fid, pin.LOCAL_WORLD_ALIGNED).vector
                            for fid in full.end_effector_frame_ids])
    arm_eq88 = arm_state.Jstar @ v_a[full.n_base:] + arm_state.J0E @ np.linalg.solve(
        arm_state.H0, state.momentum_base - H0w @ omega)
    tolerance = 1e-10 * max(1.0, np.abs(truth).max())
    assert np.allclose(state.end_effector_velocity(), truth, rtol=0.0, atol=tolerance)
    assert np.allclose(arm_eq88, truth, rtol=0.0, atol=tolerance)


def test_stored_momentum_is_pinocchios_centroidal_share(tmp_path):
    """The wheels' stored momentum from Pinocchio's centroidal map (``A_g[:, w] Omega``) is a pure
    angular momentum ``sum I_i Omega_i R a_i``, and ``momenta`` its components ``I Omega``."""
    rng = np.random.default_rng(3)
    robot = load_text(tmp_path, random_urdf(rng, 3, fixed_share=0.0), visuals=False)
    axes = rng.normal(size=(3, 3))
    wheels = mount_wheels(robot, [WheelSpec(f"w{i}", 1.0, 1.0, axis=tuple(a), inertia=0.02 * (i + 1))
                                  for i, a in enumerate(axes)])
    q, v = random_state(wheels.robot, rng, speed=10.0)
    rotation = pin.Quaternion(q[3:7]).toRotationMatrix()
    expected = rotation @ (axes / np.linalg.norm(axes, axis=1, keepdims=True)).T @ (wheels.momenta(v))
    stored = wheels.stored_momentum(q, v)
    assert np.allclose(stored[:3], 0.0, atol=1e-13)
    assert np.allclose(stored[3:], expected, rtol=0.0, atol=1e-13 * np.abs(expected).max())
    assert np.allclose(wheels.momenta(v), [0.02, 0.04, 0.06] * v[wheels.v_indices], rtol=1e-14)


def test_a_declared_wheel_is_read_from_the_urdf_and_is_no_end_effector(tmp_path):
    """A continuous joint of the URDF declared as a wheel keeps its axis (base-link frame) and
    axial inertia, and its rotor, which the loader took for an end-effector, is not one any more."""
    rng = np.random.default_rng(5)
    axis = np.array([0.0, 0.6, 0.8])
    text = random_urdf(rng, 3, fixed_share=0.0).replace("</robot>", wheel_urdf("rw", axis, np.zeros(3), 1.5, 0.07, 0.04) + "</robot>")
    robot = load_text(tmp_path, text, visuals=False)
    assert "rw_rotor" in robot.end_effectors
    wheels = mount_wheels(robot, [WheelSpec("rw", 2.0, 0.5)])
    (wheel,) = wheels.wheels
    assert "rw_rotor" not in wheels.robot.end_effectors and len(wheels.robot.arms) == len(robot.arms) - 1
    assert np.allclose(wheel.axis, axis) and wheel.inertia == pytest.approx(0.07, rel=1e-12)
    assert wheel.max_speed == pytest.approx(2.0 / 0.07)


def wheel_table(**keys) -> dict:
    """A ``[[wheels]]`` table: an added wheel about z unless ``keys`` say otherwise."""
    return {"name": "wz", "axis": [0.0, 0.0, 1.0], "max_momentum": 1.0, "max_torque": 1.0, **keys}


def scene_with(tmp_path, *wheels: dict):
    """The satellite wheel scene with the given ``[[wheels]]`` tables instead of its own."""
    import tomllib

    from .conftest import scene_variant, toml_text

    path = scene_variant(tmp_path / "w.toml", "satellite_wheels")
    raw = tomllib.loads(path.read_text())
    raw["wheels"] = list(wheels)
    path.write_text(toml_text(raw))
    from freefloat.app.scenes import load_scene

    return load_scene(path)


@pytest.mark.slow
@pytest.mark.parametrize(("table", "message"), [
    ({"joint": "no_such_joint", "max_momentum": 1.0, "max_torque": 1.0}, r"wheels\[0\]\.joint: 'no_such_joint' is not a joint"),
    ({"joint": "left_elbow_joint", "max_momentum": 1.0, "max_torque": 1.0}, r"wheels\[0\]\.joint: 'left_elbow_joint' is a .*continuous"),
    (wheel_table(axis=[0.0, 0.0, 0.0]), r"wheels\[0\]\.axis: has zero length"),
    (wheel_table(name="left_elbow_joint"), r"wheels\[0\]\.name: 'left_elbow_joint' is already a joint"),
    (wheel_table(inertia=0.1, transverse_inertia=0.01), r"wheels\[0\]: .* no rotor's"),
])
def test_a_bad_wheel_is_refused_naming_its_key(tmp_path, table, message):
    """A wheel joint that does not exist, one that is not continuous, an axis of zero length, a
    name already taken and an impossible rotor are refused when the scene is prepared, naming the
    key."""
    with pytest.raises(SceneError, match=message):
        prepare(scene_with(tmp_path, table))


@pytest.mark.parametrize(("table", "message"), [
    (wheel_table(joint="x"), r"'wheels\[0\]' needs either 'joint'"),
    ({"name": "w", "max_momentum": 1.0, "max_torque": 1.0}, r"'wheels\[0\]': an added wheel needs 'name' and an 'axis'"),
    (wheel_table(max_torque=0.0), r"'wheels.max_torque' must be > 0"),
    ({"name": "w", "axis": [0.0, 0.0, 1.0], "max_torque": 1.0}, r"\[wheels\] needs key 'max_momentum'"),
])
def test_a_bad_wheel_table_is_refused_when_read(tmp_path, table, message):
    """A wheel table with both a joint and an axis, an added wheel without its axis, a limit that
    is not positive or missing is refused by the scene schema, naming the key."""
    with pytest.raises(SceneError, match=message):
        scene_with(tmp_path, table)


def test_a_wheel_must_hang_from_the_base(tmp_path):
    """A continuous joint deeper in the tree is no reaction wheel on the base: refused naming it."""
    text = ('<robot name="r"><link name="base"><inertial><mass value="10"/><inertia ixx="1" iyy="1" izz="1" ixy="0" '
            'ixz="0" iyz="0"/></inertial></link><link name="a"><inertial><mass value="1"/><inertia ixx="0.1" '
            'iyy="0.1" izz="0.1" ixy="0" ixz="0" iyz="0"/></inertial></link><joint name="j" type="revolute">'
            '<parent link="base"/><child link="a"/><axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" '
            'velocity="1"/></joint>' + wheel_urdf("rw", np.array([0, 0, 1.0]), np.zeros(3), 1.0, 0.1, 0.1)
            .replace('<parent link="base"/>', '<parent link="a"/>') + "</robot>")
    robot = load_text(tmp_path, text, visuals=False)
    with pytest.raises(RobotModelError, match=r"wheel\.joint: 'rw' hangs from 'j'"):
        mount_wheels(robot, [WheelSpec("rw", 1.0, 1.0)])


def test_attitude_without_wheels_is_refused(tmp_path):
    """``[attitude]`` in a scene without ``[[wheels]]`` is refused, naming both."""
    with pytest.raises(SceneError, match=r"\[attitude\] drives the reaction wheels: add \[\[wheels\]\]"):
        quiet_scene(tmp_path, attitude={"kind": "hold"})


@pytest.mark.parametrize(("sections", "message"), [
    ({"robot": {"locked_joints": ["wheel_y", "left_wrist_3_joint"]}},
     r"'robot.locked_joints' names the reaction wheel wheel_y, which \[attitude\] drives"),
    ({"task": {"kind": "detumble", "rows": ["left_tool0:wz"]}}, r"'task.mission_joints' must list the arm joints"),
    ({"target": {"end_effector": "left_tool0", "second_end_effector": "right_tool0"}},
     r"\[\[wheels\]\] run in joint_space, detumbling, capture scenes; this two_hand_capture scene"),
    ({"simulation": {"model": "standard"}}, r"'simulation.model' = 'standard': a scene with \[\[wheels\]\] simulates"),
])
def test_what_wheels_cannot_go_with_is_refused(tmp_path, sections, message):
    """A locked wheel, a detumbling task that would count the wheels among its mission joints, a
    two-hand capture (its loop's squeeze law knows no wheels) or a GJM plant are refused with
    wheels, naming the key."""
    from .conftest import quiet_scene

    with pytest.raises(SceneError, match=message):
        prepare(quiet_scene(tmp_path, "satellite_wheels", **sections))


def test_declared_wheels_hold_the_base_in_a_scene(tmp_path):
    """Three continuous joints of a URDF declared as ``[[wheels]] joint = ...`` are the wheels
    the attitude law drives: their rotors are no end-effectors, and from a tumble the base's rate
    falls a hundredfold, the wheels' stored momentum balancing the rest of the robot's change."""
    from freefloat.app.runner import simulate
    from freefloat.app.scenes import parse_scene

    rng = np.random.default_rng(11)
    rotors = "".join(wheel_urdf(f"rw{i}", axis, np.zeros(3), 1.0, 0.05, 0.03) for i, axis in enumerate(np.eye(3)))
    (tmp_path / "robot.urdf").write_text(random_urdf(rng, 2, fixed_share=0.0).replace("</robot>", rotors + "</robot>"))
    scene = parse_scene({
        "name": "declared", "robot": {"urdf": "robot.urdf"},
        "initial": {"base_angular_velocity": [2.0, -1.0, 3.0]},
        "wheels": [{"joint": f"rw{i}", "max_momentum": 100.0, "max_torque": 100.0} for i in range(3)],
        "attitude": {"kp": 100.0, "kd": 20.0},
        "simulation": {"duration": 1.0, "model": "exact"}, "output": {"figures": False, "html": False},
    }, source=tmp_path / "declared.toml")
    setup = prepare(scene)
    assert not any(ee.startswith("rw") for ee in setup.robot.end_effectors)
    outcome = simulate(scene)
    rate = np.linalg.norm(outcome.telemetry.base_twist[:, 3:], axis=1)
    assert rate[-1] < 0.01 * rate[0] and not outcome.summary["wheel_saturated"]
    momentum, stored = outcome.telemetry.momentum, outcome.extra_telemetry["wheels"].stored
    drift = np.abs(momentum - momentum[0]).max()
    assert outcome.summary["wheel_momentum_balance_max"] <= 2.0 * drift + 1e-13 * np.abs(stored).max()


def test_a_wheel_out_of_a_planar_base_s_plane_is_refused_naming_its_key():
    """On a planar base a wheel must spin about z: one about x is refused naming wheels[0].axis."""
    from freefloat import load_robot

    robot = load_robot("two_arm_planar", base="planar", visuals=False)
    mount_wheels(robot, [WheelSpec("wz", 1.0, 1.0, axis=(0.0, 0.0, 2.0), key="wheels[0]")])
    with pytest.raises(RobotModelError, match=r"wheels\[0\]\.axis: wheel 'wx' spins about \[1.0, 0.0, 0.0\].*out of a "
                                              "planar base's plane"):
        mount_wheels(robot, [WheelSpec("wx", 1.0, 1.0, axis=(1.0, 0.0, 0.0), key="wheels[0]")])


def test_a_roll_attitude_on_a_planar_base_is_refused(tmp_path):
    """[attitude] rpy with a roll on a planar base (wheel about z) is refused naming attitude.rpy."""
    import tomllib

    from freefloat.app.scenes import load_scene

    from .conftest import scene_variant, toml_text

    path = scene_variant(tmp_path / "w.toml", "satellite_wheels", robot={"base": "planar"},
                         attitude={"rpy": [10.0, 0.0, 0.0]}, output={"figures": False, "html": False})
    raw = tomllib.loads(path.read_text())
    raw["wheels"] = [wheel_table()]
    path.write_text(toml_text(raw))
    with pytest.raises(SceneError, match=r"'attitude.rpy' = \[10.0, 0.0, 0.0\] rolls or pitches a planar base"):
        prepare(load_scene(path))


def test_a_rotor_above_a_planar_base_s_plane_keeps_the_planar_balance():
    """A wheel about z 0.1 m above a planar base's plane: the torque-free run's wheel balance (its
    z component, all the planar joint conserves) and momentum drift stay at round-off, though the
    joint's reactions change Lx and Ly."""
    from freefloat import load_robot
    from freefloat.app.experiments.wheel_run import wheel_telemetry
    from freefloat.dynamics.metrics import conservation
    from freefloat.dynamics.simulation import run

    robot = load_robot("two_arm_planar", base="planar", visuals=False)
    wheels = mount_wheels(robot, [WheelSpec("wz", 1.0, 1.0, axis=(0.0, 0.0, 1.0), position=(0.0, 0.0, 0.1), mass=2.0,
                                            inertia=0.05, key="wheels[0]")])
    v0 = np.random.default_rng(1).uniform(-1.0, 1.0, wheels.robot.model.nv)
    tel = run(wheels.robot, wheels.robot.neutral(), v0, 0.5, 0.005, substeps=4).telemetry
    rows = wheel_telemetry(wheels, tel, (), 0.005)
    assert np.abs(rows.rest[:, :2] - rows.rest[0, :2]).max() > 1e-4  # the reactions do change Lx, Ly
    assert np.abs(rows.balance).max() < 1e-8 and conservation(tel, wheels.robot)["momentum_drift_max"] < 1e-8


def test_wheels_moved_to_a_reduced_robot_keep_their_joints_and_a_locked_wheel_is_refused():
    """``Wheels.on`` a robot with an arm joint locked reads each wheel's indices from the reduced
    model (the rate of the same joint, by name); on one with a wheel locked it is refused naming the
    wheel."""
    from freefloat import load_robot

    robot = load_robot("two_arm_planar", base="planar", visuals=False)
    wheels = mount_wheels(robot, [WheelSpec("wz", 1.0, 1.0, axis=(0.0, 0.0, 1.0), key="wheels[0]")])
    full = wheels.robot
    q = full.neutral()
    reduced = lock_joints(full, [full.joint_names[0]], q).robot
    moved = wheels.on(reduced)
    wheel = moved.wheels[0]
    assert reduced.model.names[wheel.joint_id] == "wz" and wheel.v_index == reduced.model.idx_vs[wheel.joint_id]
    assert wheel.column == wheels.wheels[0].column - 1 and wheel.inertia == wheels.wheels[0].inertia
    with pytest.raises(RobotModelError, match=r"no joint 'wz' to carry the reaction wheel"):
        wheels.on(lock_joints(full, ["wz"], q).robot)
