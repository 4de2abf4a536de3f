"""The space-robot atlas kinds (freefloat.app.atlas.arm_maps, workspace, singularities) against
references built without the hand-built GJM: Pinocchio's frame Jacobians and centroidal map, the
four-arm robot's printed geometry, and a simulated motion to a mapped configuration."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest
from hypothesis import given, settings

from freefloat.app.atlas import singularities, workspace
from freefloat.app.atlas.arm_maps import evaluate, robot_of
from freefloat.app.atlas.engine import run_atlas
from freefloat.app.atlas.grid import Axis, Grid
from freefloat.app.atlas.kinds import Options
from freefloat.app.atlas.reach_check import drive_to
from freefloat.app.cli import main
from freefloat.errors import InvalidArgument, UnknownName
from freefloat.robot.joints import JointCoordinates

from .conftest import random_robots

pytestmark = pytest.mark.filterwarnings("ignore")


def pinocchio_blocks(context, angles: np.ndarray, momentum: np.ndarray | None = None):
    """J* and Jm blocks of the mapped end-effector (rows and arm columns as the map's), and the
    end-effector's velocity at zero joint rates under ``momentum`` [P; L about the CoM], from
    Pinocchio's frame Jacobian and centroidal momentum map: at momentum h the base velocity v_b
    solves A_b v_b = h - A_j qdot (the base rows of the conserved momenta), so J* = J_j - J_b A_b^-1 A_j."""
    robot = robot_of(context.target, context.base)
    model, data = robot.model, robot.model.createData()
    q = robot.neutral()
    JointCoordinates(robot).set(q, angles)
    pin.computeJointJacobians(model, data, q)
    pin.updateFramePlacements(model, data)
    J = pin.getFrameJacobian(model, data, robot.end_effector_frame_ids[context.index], pin.LOCAL_WORLD_ALIGNED)
    A = pin.computeCentroidalMap(model, data, q)
    kept = list(context.rows)
    nb = robot.n_base
    A_b, A_j = A[kept, :nb], A[kept, nb:]
    J_b, J_j = J[kept, :nb], J[kept, nb:]
    cols = list(context.columns)
    Jstar = (J_j - J_b @ np.linalg.solve(A_b, A_j))[:, cols]
    drift = None if momentum is None else J_b @ np.linalg.solve(A_b, momentum[kept])
    return Jstar, J_j[:, cols], drift


@pytest.mark.parametrize("target, axes", [("four_arm_planar", ("arm1_joint2", "arm1_joint3")),
                                          ("ur5", ("shoulder_lift_joint", "elbow_joint"))])
def test_singular_values_match_svd_of_pinocchio_jacobians(target, axes):
    """The map's singular values of J* and Jm equal those of Pinocchio-built Jacobians, and the
    points flagged singular are those where Pinocchio's sigma_min / sigma_max is below the tolerance."""
    context = singularities.prepare(target, Options(axes=axes))
    grid = singularities.grid(context, Options(grid=5))
    points = grid.points()
    result = evaluate(context, points)
    for k, point in enumerate(points):
        angles = np.array(context.posture)
        angles[list(context.axis_index)] = point
        Jstar, Jm, _ = pinocchio_blocks(context, angles)
        for J, key in ((Jstar, "free"), (Jm, "fixed")):
            sv = np.linalg.svd(J, compute_uv=False)
            assert np.allclose(result[f"sv_{key}"][k], sv, rtol=1e-9, atol=1e-10 * sv[0])
            assert result[f"singular_{key}"][k] == (sv[-1] < context.tolerance * sv[0])
    assert result["singular_free"].any()  # the 5-point grid holds the stretched and folded arm


@settings(max_examples=15, deadline=None)
@given(random_robots(max_links=7))
def test_random_trees_singular_values_match_pinocchio(tmp_path_factory, case):
    """On random trees (prismatic, fixed, branching joints; free base) the map of the first
    end-effector has the singular values of the J* and Jm blocks built from Pinocchio alone."""
    seed, text = case
    path = tmp_path_factory.mktemp("atlas") / "robot.urdf"
    path.write_text(text)
    context = singularities.prepare(str(path), Options())
    points = np.random.default_rng(seed).uniform(-1.0, 1.0, (4, len(context.axes)))
    result = evaluate(context, points)
    for k, point in enumerate(points):
        angles = np.array(context.posture)
        angles[list(context.axis_index)] = point
        for J, key in zip(pinocchio_blocks(context, angles)[:2], ("free", "fixed")):
            sv = np.linalg.svd(J, compute_uv=False)
            assert np.allclose(result[f"sv_{key}"][k], sv, rtol=1e-9, atol=1e-10 * max(sv[0], 1e-300))


def test_stretched_arm_is_a_rank_loss_in_pinocchio_and_on_the_map():
    """The four-arm robot's stretched arm (Table 4, figs 38-40 at 0 deg) loses rank: Pinocchio's
    J* block has sigma_min ~ 0, and the map flags it; 1 deg off it does not."""
    context = singularities.prepare("four_arm_planar", Options(axes=("arm1_joint2", "arm1_joint3")))
    result = evaluate(context, np.radians([[0.0, 0.0], [1.0, 1.0]]))
    assert list(result["singular_free"]) == [True, False] and list(result["singular_fixed"]) == [True, False]
    Jstar, _, _ = pinocchio_blocks(context, np.array(context.posture))
    sv = np.linalg.svd(Jstar, compute_uv=False)
    assert sv[-1] < 1e-12 * sv[0]


def test_momentum_drift_matches_pinocchio_and_is_held():
    """With a momentum, the drift equals Pinocchio's end-effector velocity at zero joint rates,
    and the hold rate cancels it where J* has full rank."""
    momentum = np.array([0.3, -0.2, 0.0, 0.0, 0.0, 0.5])
    context = workspace.prepare("two_arm_planar", Options(momentum=(0.3, -0.2, 0.5)))
    points = np.random.default_rng(0).uniform(-2.5, 2.5, (6, len(context.axes)))
    result = evaluate(context, points)
    for k, point in enumerate(points):
        angles = np.array(context.posture)
        angles[list(context.axis_index)] = point
        _, _, drift = pinocchio_blocks(context, angles, momentum)
        assert np.allclose(result["drift"][k], drift, atol=1e-12)
    regular = ~result["singular_free"]
    assert regular.any() and np.all(result["drift_left"][regular] < 1e-10)


def test_fixed_base_reach_of_the_four_arm_robot_is_its_printed_length():
    """Fixed base: the arm reaches 7.75 m from the base CoM (pivot 1.75 m + four links, the
    dissertation's printed end-effector position), and the map's greatest reach is that."""
    context = workspace.prepare("four_arm_planar", Options())
    result = evaluate(context, workspace.grid(context, Options(grid=5)).points())
    assert result["radius_fixed"].max() == pytest.approx(7.75, abs=1e-12)


def test_shells_split_the_reachable_radii():
    """Radii between neighbouring singular grid points make the path-dependent shells; the rest
    of the range is path-independent."""
    radius = np.linspace(1.0, 5.0, 401)
    singular = (np.abs(radius - 2.0) < 0.05) | (np.abs(radius - 2.3) < 0.05)
    split = workspace.shells(radius, singular, (401,), bins=40)
    assert split["reachable"] == [1.0, 5.0]
    assert split["path_dependent"] == [[pytest.approx(1.9), pytest.approx(2.1)],
                                       [pytest.approx(2.2), pytest.approx(2.4)]]
    assert split["path_independent"] == [[1.0, pytest.approx(1.9)], [pytest.approx(2.1), pytest.approx(2.2)],
                                         [pytest.approx(2.4), 5.0]]
    across = workspace.shells(np.array([1.0, 3.0, 2.0, 5.0]), np.array([True, True, False, False]), (2, 2), 8)
    assert across["path_dependent"] == [[1.0, 3.5]]  # the pair along the second axis fills 1 to 3 m (0.5 m bins)


def test_a_mapped_point_is_reached_by_a_simulated_motion():
    """Driven from the reference posture to grid configurations by computed torque (exact plant,
    zero momentum), the end-effector arrives where the map says: at the mapped position relative to
    the system CoM in the base frame (to 10 um: the tracking error left 0.5 s after the quintic ends),
    the CoM unmoved."""
    context = workspace.prepare("two_arm_planar", Options())
    grid = Grid(tuple(Axis(n, 0.4, 0.9, 2) for n in context.axes))
    result = evaluate(context, grid.points())
    for k in (0, grid.size - 1):
        arrival = drive_to(context, grid.points(k, k + 1)[0])
        assert arrival.com_drift < 1e-9
        assert np.allclose(arrival.ee_from_com, result["ee_from_com"][k], atol=1e-5)


def test_cli_refuses_a_robot_without_end_effectors(tmp_path, capsys):
    """A URDF with no movable joint has no end-effector to map: exit 2 naming the file."""
    urdf = tmp_path / "block.urdf"
    urdf.write_text('<robot name="block"><link name="body"><inertial><mass value="1"/><origin xyz="0 0 0"/>'
                    '<inertia ixx="1" iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/></inertial></link></robot>')
    assert main(["atlas", "workspace", str(urdf), "--quiet", "--out", str(tmp_path / "out")]) == 2
    assert "block.urdf" in capsys.readouterr().err


def test_cli_refuses_a_grid_too_large_for_memory(tmp_path, capsys):
    """A 4-axis grid of 10^4 points per axis: exit 2, saying so, before anything is written."""
    assert main(["atlas", "workspace", "four_arm_planar", "--grid", "10000", "--quiet",
                 "--out", str(tmp_path / "out")]) == 2
    assert "grid too large for memory" in capsys.readouterr().err and not (tmp_path / "out").exists()


def test_unknown_end_effector_lists_the_robot_s():
    """An end-effector that is not the robot's is refused with the valid names."""
    with pytest.raises(UnknownName, match="arm1_ee"):
        workspace.prepare("four_arm_planar", Options(end_effector="hand"))


@pytest.mark.slow
def test_cli_writes_a_singularity_map(tmp_path):
    """freefloat atlas singularities writes the data, summary and figures; the figs 38-40 paths'
    condition numbers grow as the offset shrinks."""
    out = tmp_path / "out"
    assert main(["atlas", "singularities", "four_arm_planar", "--grid", "9", "--quiet", "--out", str(out)]) == 0
    done = run_atlas("singularities", "four_arm_planar", Options(grid=9), out, overwrite=True)
    paths = done.summary["summary"]["figs_38_40"]
    assert paths["0_deg"]["condition_egjm_start"] > paths["0.1_deg"]["condition_egjm_start"] \
        > paths["1_deg"]["condition_egjm_start"]
    assert {"atlas.npz", "summary.json", "singularities_cond.png", "singularities_figs38_40.png"} \
        <= {p.name for p in out.iterdir()}


@pytest.mark.slow
def test_sigterm_keeps_the_finished_chunks_and_a_rerun_resumes(tmp_path):
    """SIGTERM to ``freefloat atlas`` once two chunks are journaled: exit 1 saying so, the chunks
    kept; the same command again finishes the map, equal to a direct evaluation."""
    import signal
    import time

    from .conftest import cli_process

    out = tmp_path / "out"
    argv = ["atlas", "workspace", "two_arm_planar", "--grid", "19", "--quiet", "--out", str(out)]
    proc = cli_process(*argv)
    journal = out / "atlas-journal.jsonl"
    deadline = time.monotonic() + 300
    while time.monotonic() < deadline and proc.poll() is None:
        if journal.is_file() and journal.read_text().count('"chunk"') >= 2:
            break
        time.sleep(0.05)
    proc.send_signal(signal.SIGTERM)
    _, err = proc.communicate(timeout=120)
    assert proc.returncode == 1 and "chunks are journaled" in err and "Traceback" not in err, err
    assert main(argv) == 0
    with np.load(out / "atlas.npz") as data:
        context = workspace.prepare("two_arm_planar", Options())
        points = workspace.grid(context, Options(grid=19)).points()
        assert np.allclose(data["radius_free"][::997], evaluate(context, points[::997])["radius_free"], rtol=1e-13)
    assert not journal.exists()


def test_the_stretched_arm_is_a_dynamic_singularity_only_through_the_system_com():
    """Stretched (joints 2-4 at zero) the four-arm robot's arm 1 is a kinematic singularity at every
    joint-1 angle, but a dynamic one (J* from Pinocchio loses rank) exactly where the arm's line
    passes through the system CoM: Vafa and Dubowsky's virtual manipulator, rooted at the CoM, is
    then stretched too. The map flags the same points."""
    context = workspace.prepare("four_arm_planar", Options())
    robot = robot_of(context.target, context.base)
    model, data = robot.model, robot.model.createData()
    q1 = np.radians([0.0, 10.0, 45.0, 90.0, 135.0, 170.0, 180.0, -30.0])
    points = np.column_stack([q1, np.zeros((len(q1), 3))])
    result = evaluate(context, points)
    for k, point in enumerate(points):
        angles = np.array(context.posture)
        angles[list(context.axis_index)] = point
        Jstar, Jm, _ = pinocchio_blocks(context, angles)
        q = robot.neutral()
        JointCoordinates(robot).set(q, angles)
        com = pin.centerOfMass(model, data, q)
        root, tip = (data.oMi[model.getJointId(f"arm1_joint{i}")].translation for i in (1, 4))
        along, to_com = (tip - root) / np.linalg.norm(tip - root), com - root
        on_line = abs(along[0] * to_com[1] - along[1] * to_com[0]) < 1e-9
        sv_free, sv_fixed = np.linalg.svd(Jstar, compute_uv=False), np.linalg.svd(Jm, compute_uv=False)
        assert sv_fixed[-1] < 1e-12 * sv_fixed[0]
        mapped = result["sv_free"][k]
        assert (sv_free[-1] < 1e-12 * sv_free[0]) == on_line == (mapped[-1] < 1e-12 * mapped[0])
    assert result["singular_fixed"].all()


def test_posture_moves_the_held_joints(tmp_path):
    """--posture sets a held joint (deg): the UR5's wrist at 0 deg is singular on the whole
    shoulder-elbow plane for the fixed base, at 60 deg nowhere but at the stretched and folded
    elbow; an unknown joint is refused with the robot's joints."""
    axes = ("shoulder_lift_joint", "elbow_joint")
    wrist = singularities.prepare("ur5", Options(axes=axes, posture=(("wrist_2_joint", 60.0),)))
    assert wrist.posture[4] == pytest.approx(np.radians(60.0))
    points = singularities.grid(wrist, Options(grid=9)).points()
    bent = evaluate(wrist, points)
    held = evaluate(singularities.prepare("ur5", Options(axes=axes)), points)
    assert held["singular_fixed"].all()
    elbow = np.isclose(np.abs(points[:, 1]) % np.pi, 0.0)
    assert np.array_equal(bent["singular_fixed"], elbow)
    with pytest.raises(UnknownName, match="wrist_2_joint"):
        singularities.prepare("ur5", Options(posture=(("wrist", 1.0),)))
    assert main(["atlas", "singularities", "ur5", "--posture", "wrist_2_joint:60", "--quiet",
                 "--out", str(tmp_path / "out")]) == 2


def test_posture_of_a_mapped_axis_is_refused_naming_it():
    """--posture on a joint the map sweeps (an axis) is refused naming the joint and the axes."""
    with pytest.raises(InvalidArgument, match="'elbow_joint' is an axis of the map"):
        singularities.prepare("ur5", Options(axes=("shoulder_lift_joint", "elbow_joint"),
                                             posture=(("elbow_joint", 30.0),)))


@pytest.mark.parametrize("momentum", [(1e300, 0, 0), (0, 0, float("inf"))])
def test_a_momentum_beyond_any_robot_s_or_not_finite_is_refused(momentum):
    """A momentum component that is not finite or beyond MAX_MOMENTUM is refused, not mapped into infinities."""
    with pytest.raises(InvalidArgument, match="momentum= takes .* at most 1e\\+15"):
        workspace.prepare("four_arm_planar", Options(momentum=momentum))


def test_out_of_plane_momentum_on_a_planar_base_is_refused_naming_the_components():
    """On a planar base, a 6-vector momentum with Pz or Lx is refused naming them, not dropped."""
    with pytest.raises(InvalidArgument, match="gives Pz, Lx = 5, 1 on a planar base"):
        workspace.prepare("four_arm_planar", Options(momentum=(0, 0, 5, 1, 0, 0)))

