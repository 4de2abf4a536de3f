"""Mechanism maps (freefloat.parallel.maps): the 5R's workspace against its closed-form annuli,
type I points at stretched or folded legs, type II points where the direct kinematics blows up,
and every assembly and working mode closed by Pinocchio's kinematics of the URDF (map points
reached by a simulated motion: tests/test_atlas_mechanism_maps.py)."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from freefloat.errors import BadShape, FreefloatError
from freefloat.parallel.five_bar import FiveBarParameters, elbow_guess, five_bar
from freefloat.parallel.maps import five_bar_exact as exact
from freefloat.parallel.maps.grids import axes_grid, boundary, joint_map, task_map
from freefloat.parallel.maps.jacobians import closure, partition
from freefloat.parallel.maps.loci import loci
from freefloat.parallel.maps.modes import (
    assembly_label,
    assembly_modes,
    direct_solutions,
    working_label,
    working_modes,
)
from freefloat.parallel.maps.solve import newton
from freefloat.parallel.registry import REGISTRY
from freefloat.paths import URDF_DIR

P = FiveBarParameters()
N = 31
FIVE_BAR_BOX = np.array([[-0.33, 0.33], [-0.33, 0.33]])


@pytest.fixture(scope="module")
def setups():
    return {name: REGISTRY[name].build(URDF_DIR / f"{name}.closure.toml", "nominal") for name in ("five_bar", "rsu_ppap")}


@pytest.fixture(scope="module")
def task():
    mech = five_bar(P)
    grid = task_map(mech, axes_grid([np.linspace(*FIVE_BAR_BOX[0], N), np.linspace(*FIVE_BAR_BOX[1], N)]))
    return mech, grid, {locus.kind: locus for locus in loci(mech, grid, (N, N), "task")}


@pytest.fixture(scope="module")
def joint():
    mech = five_bar(P)
    axis = np.linspace(-np.pi, np.pi, N)
    grid = joint_map(mech, axes_grid([axis, axis]), FIVE_BAR_BOX, count=16)
    return mech, grid, {locus.kind: locus for locus in loci(mech, grid, (N, N), "joint")}


def elbows(q: np.ndarray) -> np.ndarray:
    """The 5R's elbows E_1, E_2 (..., 2, 2), m, from its joints, by planar geometry (not the DH code)."""
    a = np.array([P.l0, -P.l0])
    x = a + np.array([1.0, -1.0]) * P.l1 * np.cos(q[..., [2, 4]])   # chain 2's base is mirrored in x
    return np.stack((x, P.l1 * np.sin(q[..., [2, 4]])), axis=-1)


def pinocchio_closure(chain, q: np.ndarray) -> float:
    """Largest loop-closure error (m, rad) of Orsino's ``q`` (n_q,) by Pinocchio's forward
    kinematics of the URDF spanning tree and its RigidConstraintModels."""
    model, data = chain.model, chain.model.createData()
    pin.forwardKinematics(model, data, chain.pinocchio_q(q))
    worst = 0.0
    for c in chain.constraints:
        M1, M2 = data.oMi[c.joint1_id] * c.joint1_placement, data.oMi[c.joint2_id] * c.joint2_placement
        gap = pin.log6(M1.inverse() * M2).vector if c.type == pin.ContactType.CONTACT_6D else M2.translation - M1.translation
        worst = max(worst, np.abs(gap).max())
    return worst


@pytest.mark.slow
def test_five_bar_workspace_is_the_annuli_intersection(task):
    """A point has a working mode exactly where it lies in both annuli (|l1 - l2| <= |P - A_i| <= l1 + l2)."""
    _, grid, _ = task
    np.testing.assert_array_equal(grid.modes.found.any(axis=1), exact.contains(P, grid.coordinates))


def test_five_bar_boundary_arcs_end_at_the_circle_intersections():
    """Each exact boundary arc lies on its circle and ends where it meets a circle of the other
    leg (intersection points computed here in closed form); a circle wholly inside the other
    annulus (the folded circles here) is one closed arc."""
    inner, outer = abs(P.l1 - P.l2), P.l1 + P.l2
    arcs = exact.boundary(P, samples=20000)
    crossings = []
    for r1 in (inner, outer):
        for r2 in (inner, outer):
            d = 2 * P.l0                                         # centres (l0, 0) and (-l0, 0)
            a = (d * d + r1 * r1 - r2 * r2) / (2 * d)
            if r1 > abs(a):
                h = np.sqrt(r1 * r1 - a * a)
                crossings += [(P.l0 - a, h), (P.l0 - a, -h)]
    crossings = np.array(crossings)
    for arc in arcs:
        centre = exact.bases(P)[arc.leg]
        np.testing.assert_allclose(np.linalg.norm(arc.points - centre, axis=1), outer if arc.stretched else inner, atol=1e-15)
        if np.array_equal(arc.points[0], arc.points[-1]):
            assert not arc.stretched
            continue
        for end in (arc.points[0], arc.points[-1]):
            assert np.linalg.norm(crossings - end, axis=1).min() < 2 * np.pi * outer / 20000


def test_five_bar_area_matches_the_grid():
    """The closed-form area of the annuli's intersection is what a fine grid counts."""
    axis = np.linspace(-0.33, 0.33, 1201)
    inside = exact.contains(P, axes_grid([axis, axis]))
    assert inside.mean() * 0.66**2 == pytest.approx(exact.area(P), rel=5e-3)


@pytest.mark.slow
@settings(max_examples=12, deadline=None)
@given(l0=st.floats(0.01, 0.2), l1=st.floats(0.05, 0.3), l2=st.floats(0.05, 0.3),
       seed=st.integers(0, 2**16))
def test_random_five_bars_reach_their_annuli_in_four_modes(l0, l1, l2, seed):
    """On random 5R geometries, random points have all four working modes where they lie in both
    annuli (away from the circles by 1e-6 m) and none elsewhere, and every mode closes the loop."""
    p = FiveBarParameters(l0=l0, l1=l1, l2=l2)
    mech = five_bar(p)
    reach = l0 + l1 + l2
    points = np.random.default_rng(seed).uniform(-reach, reach, (40, 2))
    r = np.linalg.norm(points[:, None] - exact.bases(p), axis=-1)
    clear = (np.abs(r[..., None] - np.array(exact.radii(p))) > 1e-6).all(axis=(1, 2))
    modes = working_modes(mech, points[clear], count=16)
    inside = exact.contains(p, points[clear])
    np.testing.assert_array_equal(modes.found.all(axis=1), inside)
    np.testing.assert_array_equal(modes.found.any(axis=1), inside)
    assert np.abs(closure(mech, modes.q[inside])[0]).max(initial=0.0) < 1e-10


def test_grid_boundary_cells_are_inside_next_to_outside():
    """The boundary of a disc on a grid is its inside cells with an outside neighbour."""
    axis = np.linspace(-1, 1, 21)
    x = axes_grid([axis, axis]).reshape(21, 21, 2)
    inside = np.linalg.norm(x, axis=-1) <= 0.7
    edge = boundary(inside)
    assert edge[inside].sum() < inside.sum() and not edge[~inside].any()
    assert not boundary(np.ones((5, 5), bool)).any()


@pytest.mark.slow
def test_type_one_points_are_stretched_or_folded_legs(task):
    """Every type I point of the task map: A[:, joints] is rank deficient (SVD), and one leg
    reaches exactly l1 + l2 or |l1 - l2| from its base (analytic)."""
    mech, _, found = task
    locus = found["I"]
    assert len(locus.mode) > 50
    s = np.linalg.svd(closure(mech, locus.q)[1][:, :, 2:], compute_uv=False)
    assert (s[:, -1] / s[:, 0]).max() < 1e-4
    r = np.linalg.norm(locus.coordinates[:, None] - exact.bases(P), axis=-1)
    gap = np.abs(r[:, :, None] - np.array(exact.radii(P))).reshape(len(r), -1).min(axis=1)
    assert gap.max() < 1e-9


@pytest.mark.slow
def test_type_two_points_align_the_distal_links_and_blow_up_the_direct_kinematics(task):
    """Every type II point of the task map: [A_platform, A_passive] is rank deficient (SVD), the
    elbows and the platform point are collinear, and the direct kinematics' Jacobian
    d(platform)/d(actuated) (the inverse of the inverse kinematics' Jacobian by finite differences)
    is orders larger there than at the scenes' start."""
    mech, _, found = task
    locus = found["II"]
    assert len(locus.mode) > 20
    part = partition(mech)
    s = np.linalg.svd(closure(mech, locus.q)[1][:, :, part.unactuated], compute_uv=False)
    assert (s[:, -1] / s[:, 0]).max() < 1e-6
    e = elbows(locus.q)
    u, v = e[:, 0] - locus.coordinates, e[:, 1] - locus.coordinates
    np.testing.assert_allclose(u[:, 0] * v[:, 1] - u[:, 1] * v[:, 0], 0.0, atol=1e-9)

    def inverse_sigma(q: np.ndarray, h: float = 1e-7) -> float:
        """sigma_min of d(actuated)/d(platform) by central differences of the inverse kinematics
        in the same working mode: ||d(platform)/d(actuated)|| is its inverse."""
        cols = []
        for k in part.platform:
            pair = np.array([q, q])
            pair[:, k] += [h, -h]
            solved, ok = newton(mech, pair, part.joints)
            assert ok.all()
            cols.append((solved[0, part.actuated] - solved[1, part.actuated]) / (2 * h))
        return np.linalg.svd(np.array(cols).T, compute_uv=False)[-1]

    start = mech.assemble(np.array([0.07, 0.17]), elbow_guess(P, np.array([0.07, 0.17])))
    regular = inverse_sigma(start)
    near = [inverse_sigma(q) for q in locus.q[:: max(1, len(locus.q) // 5)]]
    assert max(near) < regular / 100


@pytest.mark.slow
def test_joint_space_loci_swap_the_types(joint):
    """In actuated-joint space type I points still fold or stretch a leg (SVD of A[:, joints]) and
    type II points end an assembly mode with the distal links aligned (SVD of the direct block)."""
    mech, grid, found = joint
    part = partition(mech)
    assert grid.modes.labels == ("+", "-") and grid.modes.found.sum() > 0
    one, two = found["I"], found["II"]
    assert len(one.mode) > 20 and len(two.mode) > 20
    A1, A2 = closure(mech, one.q)[1], closure(mech, two.q)[1]
    s1 = np.linalg.svd(A1[:, :, part.joints], compute_uv=False)
    s2 = np.linalg.svd(A2[:, :, part.unactuated], compute_uv=False)
    assert (s1[:, -1] / s1[:, 0]).max() < 1e-6 and (s2[:, -1] / s2[:, 0]).max() < 1e-4


@pytest.mark.parametrize("name, point, modes", [("five_bar", [0.07, 0.17], 4), ("rsu_ppap", [0.03, 0.0, 0.40], 8)])
def test_working_modes_close_the_loops_by_pinocchio(setups, name, point, modes):
    """Every working mode at the scenes' start closes the loops to 1e-10 by Pinocchio's forward
    kinematics of the URDF; they are physically distinct poses; the scenes' pose is one of them."""
    setup = setups[name]
    mech = setup.nominal
    found = working_modes(mech, np.array([point]), count=32)
    assert found.found.all() and len(found.labels) == modes
    for q in found.q[0]:
        assert pinocchio_closure(setup.display, q) < 1e-10
    joints = np.array([np.concatenate([f[:, :3, 3].ravel() for f in (c.frames(qi)[1] for c, qi in zip(mech.chains, mech.split(q)))])
                       for q in found.q[0]])
    assert min(np.linalg.norm(joints[i] - joints[j]) for i in range(modes) for j in range(i)) > 1e-3
    scene = mech.assemble(np.array(point), setup.guess(np.array(point)))
    label = str(working_label(mech, scene))
    np.testing.assert_allclose(found.mode(label)[0][0, mech.actuated], scene[mech.actuated], atol=1e-9)


@pytest.mark.parametrize("name, point, box", [("five_bar", [0.07, 0.17], FIVE_BAR_BOX),
                                              ("rsu_ppap", [0.03, 0.0, 0.40], [[-0.3, 0.1], [-0.2, 0.2], [0.0, 0.7]])])
def test_assembly_modes_close_the_loops_by_pinocchio(setups, name, point, box):
    """Both assembly modes at the scenes' actuated joints close the loops to 1e-10 by Pinocchio;
    the scenes' pose is the one of its sign, and the other holds the same actuated joints."""
    setup = setups[name]
    mech = setup.nominal
    scene = mech.assemble(np.array(point), setup.guess(np.array(point)))
    found = assembly_modes(mech, scene[None, mech.actuated], np.array(box, float), count=64)
    assert found.found.all()
    for q in found.q[0]:
        assert pinocchio_closure(setup.display, q) < 1e-10
        np.testing.assert_allclose(q[mech.actuated], scene[mech.actuated], atol=1e-14)
    mine = found.mode(str(assembly_label(mech, scene)))[0][0]
    np.testing.assert_allclose(mine[: mech.p], scene[: mech.p], atol=1e-9)


@pytest.mark.parametrize("name, point, box, count", [("five_bar", [0.07, 0.17], FIVE_BAR_BOX, 2),
                                                     ("rsu_ppap", [0.03, 0.0, 0.40], [[-0.3, 0.1], [-0.2, 0.2], [-0.7, 0.7]], 4)])
def test_direct_kinematics_solutions_are_distinct_closed_poses(setups, name, point, box, count):
    """Every distinct solution of the direct kinematics at the scenes' actuated joints closes the
    loops by Pinocchio (1e-10) at those joints: the 5R's two (the platform on either side of the
    line through its elbows), the 2RSU+PPaP's four (the platform above or below the cranks,
    times the bars up or down); the scenes' pose is one of them."""
    setup = setups[name]
    mech = setup.nominal
    scene = mech.assemble(np.array(point), setup.guess(np.array(point)))
    found = direct_solutions(mech, scene[mech.actuated], np.array(box, float))
    assert len(found) == count
    for q in found:
        assert pinocchio_closure(setup.display, q) < 1e-10
        np.testing.assert_allclose(q[mech.actuated], scene[mech.actuated], atol=1e-14)
    assert np.abs(found[:, : mech.p] - scene[: mech.p]).max(axis=1).min() < 1e-9


@pytest.mark.slow
def test_five_bar_working_modes_are_the_elbow_combinations(task):
    """The 5R's working modes at a point hold, per leg, the two closed-form base angles
    ``atan2(y, x) -+ atan2(l2 sin q2, l1 + l2 cos q2)``, ``q2 = +-arccos(c)`` (chain 2 mirrored)."""
    _, grid, _ = task
    checked = 0
    for x, q, found in zip(grid.coordinates, grid.modes.q, grid.modes.found):
        locals_ = [np.array([x[0] - P.l0, x[1]]), np.array([-(x[0] + P.l0), x[1]])]
        cosines = [(v @ v - P.l1**2 - P.l2**2) / (2 * P.l1 * P.l2) for v in locals_]
        if not found.all() or max(abs(c) for c in cosines) > 1 - 1e-6:
            continue
        for column, v, c in zip((2, 4), locals_, cosines):
            want = np.sort([np.angle(np.exp(1j * (np.arctan2(v[1], v[0]) - np.arctan2(P.l2 * np.sin(e), P.l1 + P.l2 * np.cos(e)))))
                            for e in (np.arccos(c), -np.arccos(c))])
            np.testing.assert_allclose(np.sort(np.unique(np.round(q[:, column], 9))), want, atol=1e-8)
        checked += 1
    assert checked > 300


@pytest.mark.slow
def test_rsu_ppap_workspace_is_where_every_leg_reaches(setups):
    """On an (x, z) grid through the scenes' start, the 2RSU+PPaP's map has its eight working
    modes exactly where each leg reaches the platform in closed form: the crank's circle within a
    rod's length of the universal joint, the parallelogram's bars spanning x (the scene's
    assembly guess, which raises otherwise)."""
    from freefloat.parallel.rsu_ppap import assembly_guess, load_data

    mech, data = setups["rsu_ppap"].nominal, load_data()
    axis_x, axis_z = np.linspace(-0.33, 0.12, 8), np.linspace(0.05, 0.65, 8)
    points = axes_grid([axis_x, np.array([0.0]), axis_z])
    found = working_modes(mech, points, count=32).found

    def reaches(x: np.ndarray) -> bool:
        try:
            assembly_guess(data, x)
        except FreefloatError:
            return False
        return True

    expected = np.array([reaches(x) for x in points])
    assert 0 < expected.sum() < len(points)
    np.testing.assert_array_equal(found.all(axis=1), expected)
    np.testing.assert_array_equal(found.any(axis=1), expected)


@pytest.mark.slow
def test_rsu_ppap_type_one_points_stretch_a_crank_and_rod_or_lay_the_bars_flat(setups):
    """Every type I point of a 9 x 9 (x, z) map of the 2RSU+PPaP: the inverse block is rank
    deficient (SVD) and, by the leg's geometry, either an RSU leg's rod lies in the plane of its
    crank's motion direction and the crank axis (so the crank cannot change the rod's length:
    crank and rod stretched or folded in projection) or the parallelogram's bars are horizontal."""
    mech = setups["rsu_ppap"].nominal
    points = axes_grid([np.linspace(-0.33, 0.12, 9), np.array([0.0]), np.linspace(0.05, 0.65, 9)])
    locus = {l.kind: l for l in loci(mech, task_map(mech, points, count=32), (9, 1, 9), "task")}["I"]
    assert len(locus.q) > 50
    s = np.linalg.svd(closure(mech, locus.q)[1][:, :, partition(mech).joints], compute_uv=False)
    assert (s[:, -1] / s[:, 0]).max() < 1e-5
    measures = []
    for chain, q in zip(mech.chains[:2], mech.split(locus.q)[:2]):
        joints = chain.frames(q)[1][..., :3, 3]               # pivot, crank tip (spherical centre) ..., universal centre
        pivot, tip, universal = joints[:, 0], joints[:, 1], joints[:, 4]
        motion = np.cross([0.0, 1.0, 0.0], tip - pivot)        # the crank tip's direction of motion
        rod = universal - tip
        measures.append(np.abs(np.einsum("ij,ij->i", rod, motion)) / np.linalg.norm(rod, axis=1) / np.linalg.norm(motion, axis=1))
    measures.append(np.abs(np.sin(mech.split(locus.q)[2][:, 1])))   # the parallelogram's bar angle
    assert np.min(measures, axis=0).max() < 1e-4


def test_bad_inputs_are_refused():
    """Points of the wrong width and a box of the wrong shape raise BadShape naming them; a
    redundantly actuated mechanism is refused."""
    mech = five_bar(P)
    with pytest.raises(BadShape, match="points"):
        working_modes(mech, np.zeros((2, 3)))
    with pytest.raises(BadShape, match="box"):
        assembly_modes(mech, np.zeros((1, 2)), np.zeros((3, 2)))
    from dataclasses import replace
    with pytest.raises(FreefloatError, match="actuators"):
        partition(replace(mech, actuated=np.array([2, 3, 4])))
