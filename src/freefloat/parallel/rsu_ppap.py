"""The 2RSU+PPaP: a 3-DOF translational parallel mechanism (thesis proposal, secs 1 and 5.4).

No dimensions of the EPUSP prototype are public; every number is assumed and lives in
``urdf/rsu_ppap.data.toml``. From it :func:`rsu_ppap_urdf` writes the spanning tree
``urdf/rsu_ppap.urdf`` (frames below), and ``urdf/rsu_ppap.closure.toml`` states its three loop
closures and the actuated joints.

Spanning tree (z up; every joint frame is parallel to the inertial one at zero angles):

* RSU leg i (i = 1, 2): ``rsu<i>_crank`` about y at the pivot (the crank points along the data's
  ``crank`` direction at zero), the spherical joint as ``rsu<i>_s1/_s2/_s3`` about z, y, x at the crank tip, the rod
  along +z of ``rsu<i>_rod``, the universal joint ``rsu<i>_u1/_u2`` about x, y at the rod tip;
  the frame ``rsu<i>_tip`` on its outer piece.
* PPaP leg: ``ppap_rail`` along y, the parallelogram's bars ``ppap_bar1`` (about y on the
  slider, along +x at zero) and ``ppap_bar2`` (parallel, ``bar_spacing`` above it), the coupler
  ``ppap_coupler`` about y at bar 1's tip, the lift ``ppap_lift`` along z carrying the ``platform``, whose frame is q#.
* Closures: ``rsu<i>_tip`` = ``platform_a<i>`` as frames (6-D: the universal joint's outer piece
  is fixed to the platform), ``ppap_bar2_tip`` = ``ppap_pivot2`` as points (the parallelogram).

Orsino's model (:func:`load_rsu_ppap`): platform coordinates q# = (x, y, z) of the platform
centre (a massless point; the platform body rides on the PPaP chain's last link); chains RSU 1,
RSU 2 (6 joints each) and PPaP (rail, bar 1, coupler, lift), so ``q`` has 3 + 16 coordinates.
Linear constraints: each chain tip at ``q# + attach_i`` (9 rows). Angular constraints (eq 101,
7 rows): the RSU tips do not turn (``Q`` picks their angular velocities; P = 0, the platform
only translates), and the parallelogram keeps the coupler parallel to the slider,
``qdot_bar1 + qdot_coupler = 0`` (an ``R`` row). Bar 2 moves as bar 1 translated by a constant
offset on the slider, so its mass and inertia (in its own frame) add to bar 1's exactly; Orsino's
model needs no fourth chain for it.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
import pinocchio as pin

from ..errors import FreefloatError
from ..inputs import read_toml, reject_unknown
from ..paths import URDF_DIR
from .closed_chain import ClosedChain, chain_from_tree, read_closures
from .mechanism import AngularConstraints, ParallelMechanism

if TYPE_CHECKING:  # the URDF writer's types; yourdfpy (trimesh, networkx: 0.2-0.6 s) loads when it writes
    import yourdfpy

DATA = URDF_DIR / "rsu_ppap.data.toml"
CLOSURE = URDF_DIR / "rsu_ppap.closure.toml"
LEGS = ("rsu1", "rsu2")
#: Joints of each chain, base outwards, in Orsino's coordinate order after q#.
CHAIN_JOINTS = tuple(tuple(f"{leg}_{j}" for j in ("crank", "s1", "s2", "s3", "u1", "u2")) for leg in LEGS) + (
    ("ppap_rail", "ppap_bar1", "ppap_coupler", "ppap_lift"),)
#: The slides' limits (effort N, velocity m/s, position m) in the URDF :func:`rsu_ppap_urdf` writes.
SLIDE_LIMIT = {"effort": 1000.0, "velocity": 10.0, "lower": -1.0, "upper": 1.0}
#: Every key of the data file with its shape (``()``: a positive number).
_KEYS = {"": {"home": (3,)},
         "platform": {"mass": (), "size": (3,), "attach": (2, 3)},
         "rsu": {"pivot": (2, 3), "crank": (2, 3), "crank_length": (), "crank_mass": (), "rod_length": (), "rod_mass": (),
                 "rod_radius": (), "joint_mass": (), "joint_radius": ()},
         "ppap": {"rail": (3,), "slider_mass": (), "slider_size": (3,), "bar_length": (), "bar_spacing": (), "bar_mass": (),
                  "bar_radius": (), "coupler_mass": (), "coupler_size": (3,), "lift_offset": ()}}
#: The bodies' masses, as keys of the data file: the parameters ``[uncertainty]`` may name.
MASSES = ("platform.mass", "rsu.crank_mass", "rsu.rod_mass", "rsu.joint_mass", "ppap.slider_mass", "ppap.bar_mass",
          "ppap.coupler_mass")


def load_data(path: str | Path = DATA) -> dict:
    """The assumed numbers of the 2RSU+PPaP (see the file's comments).

    Raises:
        FreefloatError: naming the file and the key that is missing, not numeric, of the wrong
            shape, not positive (masses, lengths), a crank direction that is not +-x or +-z, or
            an ``[uncertainty]`` table that is missing, names no mass, or gives a half-width not
            in (0, nominal mass).
    """
    path = Path(path)
    data = read_toml(path, "2RSU+PPaP data file")
    for section, keys in _KEYS.items():
        table = data.get(section, {}) if section else data
        if not isinstance(table, dict):
            raise FreefloatError(f"{path}: '{section}' must be a table, got {table!r}")
        tables = [] if section else [*(s for s in _KEYS if s), "uncertainty"]
        reject_unknown(f"{path}: ", table, [*keys, *tables], section)
        for key, shape in keys.items():
            name = f"{section}.{key}" if section else key
            if key not in table:
                raise FreefloatError(f"{path}: missing key '{name}'")
            if not _numeric(table[key]):
                raise FreefloatError(f"{path}: '{name}' must be numeric, got {table[key]!r}")
            value = np.asarray(table[key], dtype=float)
            if value.shape != shape or not np.isfinite(value).all() or (shape == () and value <= 0.0):
                what = "a positive number" if shape == () else f"finite numbers of shape {shape}"
                raise FreefloatError(f"{path}: '{name}' must be {what}, got {table[key]!r}")
    for i, crank in enumerate(np.asarray(data["rsu"]["crank"], float)):
        if sorted(np.abs(crank)) != [0.0, 0.0, 1.0] or crank[1] != 0.0:
            raise FreefloatError(f"{path}: 'rsu.crank' [{i}] must be a unit vector along x or z (perpendicular to the "
                                 f"crank axis y), got {crank.tolist()}")
    _check_uncertainty(path, data)
    return data


def mass(data: dict, key: str) -> float:
    """The nominal mass (kg) of a key of :data:`MASSES` (``"section.key"``)."""
    section, name = key.split(".")
    return float(data[section][name])


def _check_uncertainty(path: Path, data: dict) -> None:
    """``[uncertainty]``: half-widths (kg) of some of :data:`MASSES`, each in (0, nominal)."""
    table = data.get("uncertainty")
    if not isinstance(table, dict) or not table:
        raise FreefloatError(f"{path}: missing table 'uncertainty' (half-widths of the uncertain masses, kg, keyed by "
                             f"any of {', '.join(MASSES)})")
    reject_unknown(f"{path}: ", table, MASSES, "uncertainty")
    for key, value in table.items():
        if not _numeric(value) or isinstance(value, list) or not 0.0 < value < mass(data, key):
            raise FreefloatError(f"{path}: 'uncertainty.\"{key}\"' must be a number in (0, {mass(data, key)}) kg "
                                 f"(the nominal mass: a mass stays positive), got {value!r}")


def _numeric(value) -> bool:
    """Whether a TOML value is a number or (nested) lists of numbers (not strings or booleans)."""
    if isinstance(value, list):
        return all(_numeric(v) for v in value)
    return isinstance(value, (int, float)) and not isinstance(value, bool)


def _rod_inertia(mass: float, length: float, radius: float, axis: int) -> list[float]:
    """Principal inertias (3,) of a solid cylinder along ``axis`` about its centre, kg m^2."""
    across = mass * (3.0 * radius**2 + length**2) / 12.0
    out = [across] * 3
    out[axis] = 0.5 * mass * radius**2
    return out


def _box_inertia(mass: float, size) -> list[float]:
    a, b, c = size
    return [mass * (b * b + c * c) / 12.0, mass * (a * a + c * c) / 12.0, mass * (a * a + b * b) / 12.0]


def _cylinder(radius: float, length: float, centre: np.ndarray) -> yourdfpy.Visual:
    """A cylinder centred at ``centre`` (3,) along the axis ``centre`` points on (x, y or z)."""
    import yourdfpy

    from ..robot.builders import pose

    axis = int(np.argmax(np.abs(centre)))
    rpy = [(0.0, np.pi / 2, 0.0), (np.pi / 2, 0.0, 0.0), (0.0, 0.0, 0.0)][axis]
    return yourdfpy.Visual(origin=pose(centre, rpy), geometry=yourdfpy.Geometry(cylinder=yourdfpy.Cylinder(radius, length)))


def rsu_ppap_urdf(data: dict) -> yourdfpy.URDF:
    """The spanning tree of the 2RSU+PPaP (module docstring) from :func:`load_data`'s numbers."""
    import yourdfpy

    from ..robot.builders import JOINT_LIMIT, body_link, box_visual, pose, wrap_robot

    slide_limit = yourdfpy.Limit(**SLIDE_LIMIT)
    rsu, ppap, plat = data["rsu"], data["ppap"], data["platform"]
    links = [body_link("base", 1.0, (0.01, 0.01, 0.01), (0.0, 0.0, 0.0), box_visual((0.5, 0.7, 0.02)))]
    joints = []

    def add(name: str, kind: str, parent: str, xyz, axis, link: yourdfpy.Link | None) -> None:
        child = link or yourdfpy.Link(name=name)
        links.append(child)
        joints.append(yourdfpy.Joint(name=name if kind != "fixed" else f"{name}_fixed", type=kind, parent=parent,
                                     child=child.name, origin=pose(xyz, (0.0, 0.0, 0.0)),
                                     axis=None if axis is None else np.array(axis, float),
                                     limit={"revolute": JOINT_LIMIT, "prismatic": slide_limit}.get(kind)))

    m_j, r_j = rsu["joint_mass"], rsu["joint_radius"]
    sphere = [0.4 * m_j * r_j**2] * 3
    knuckle = yourdfpy.Visual(origin=np.eye(4), geometry=yourdfpy.Geometry(sphere=yourdfpy.Sphere(r_j)))
    lc, lr = rsu["crank_length"], rsu["rod_length"]
    for i, leg in enumerate(LEGS):
        crank = np.asarray(rsu["crank"][i], float)
        add(f"{leg}_crank", "revolute", "base", rsu["pivot"][i], (0, 1, 0),
            body_link(f"{leg}_crank", rsu["crank_mass"],
                      _rod_inertia(rsu["crank_mass"], lc, rsu["rod_radius"], int(np.argmax(np.abs(crank)))),
                      0.5 * lc * crank, _cylinder(rsu["rod_radius"], lc, 0.5 * lc * crank)))
        parent = f"{leg}_crank"
        for name, axis, xyz in (("s1", (0, 0, 1), lc * crank), ("s2", (0, 1, 0), (0.0, 0.0, 0.0))):
            add(f"{leg}_{name}", "revolute", parent, xyz, axis, body_link(f"{leg}_{name}", m_j, sphere, (0, 0, 0), knuckle))
            parent = f"{leg}_{name}"
        add(f"{leg}_s3", "revolute", parent, (0.0, 0.0, 0.0), (1, 0, 0),
            body_link(f"{leg}_rod", rsu["rod_mass"], _rod_inertia(rsu["rod_mass"], lr, rsu["rod_radius"], 2),
                      (0.0, 0.0, 0.5 * lr), _cylinder(rsu["rod_radius"], lr, np.array([0.0, 0.0, 0.5 * lr]))))
        add(f"{leg}_u1", "revolute", f"{leg}_rod", (0.0, 0.0, lr), (1, 0, 0),
            body_link(f"{leg}_u1", m_j, sphere, (0, 0, 0), knuckle))
        add(f"{leg}_u2", "revolute", f"{leg}_u1", (0.0, 0.0, 0.0), (0, 1, 0),
            body_link(f"{leg}_u2", m_j, sphere, (0, 0, 0), knuckle))
        add(f"{leg}_tip", "fixed", f"{leg}_u2", (0.0, 0.0, 0.0), None, None)

    lb, h = ppap["bar_length"], ppap["bar_spacing"]
    add("ppap_rail", "prismatic", "base", ppap["rail"], (0, 1, 0),
        body_link("ppap_slider", ppap["slider_mass"], _box_inertia(ppap["slider_mass"], ppap["slider_size"]),
                  (0, 0, 0), box_visual(ppap["slider_size"])))
    bar = _rod_inertia(ppap["bar_mass"], lb, ppap["bar_radius"], 0)
    for name, xyz in (("ppap_bar1", (0.0, 0.0, 0.0)), ("ppap_bar2", (0.0, 0.0, h))):
        add(name, "revolute", "ppap_slider", xyz, (0, 1, 0),
            body_link(name, ppap["bar_mass"], bar, (0.5 * lb, 0.0, 0.0),
                      _cylinder(ppap["bar_radius"], lb, np.array([0.5 * lb, 0.0, 0.0]))))
    add("ppap_bar2_tip", "fixed", "ppap_bar2", (lb, 0.0, 0.0), None, None)
    add("ppap_coupler", "revolute", "ppap_bar1", (lb, 0.0, 0.0), (0, 1, 0),
        body_link("ppap_coupler", ppap["coupler_mass"], _box_inertia(ppap["coupler_mass"], ppap["coupler_size"]),
                  (0.0, 0.0, 0.5 * h), box_visual(ppap["coupler_size"])))
    add("ppap_pivot2", "fixed", "ppap_coupler", (0.0, 0.0, h), None, None)
    add("ppap_lift", "prismatic", "ppap_coupler", (ppap["lift_offset"], 0.0, 0.0), (0, 0, 1),
        body_link("platform", plat["mass"], _box_inertia(plat["mass"], plat["size"]), (0, 0, 0), box_visual(plat["size"])))
    for i, attach in enumerate(plat["attach"], start=1):
        add(f"platform_a{i}", "fixed", "platform", attach, None, None)
    return wrap_robot(yourdfpy.Robot(name="rsu_ppap", links=links, joints=joints))


def load_rsu_ppap(closure: str | Path = CLOSURE) -> ClosedChain:
    """Orsino's model and Pinocchio's constrained model of the 2RSU+PPaP (module docstring), both
    from the closure file and its URDF (the attachment points are read from the platform's
    frames ``platform_a<i>``).

    Raises:
        FreefloatError: as :func:`read_closures`; naming the chain or frame when the tree is not
            the 2RSU+PPaP's (joints, or a platform not parallel to the inertial frame).
    """
    closures = read_closures(closure)
    model = pin.Model(closures.model)
    bar1, bar2 = model.getJointId("ppap_bar1"), model.getJointId("ppap_bar2")
    model.inertias[bar1] = model.inertias[bar1] + model.inertias[bar2]
    for terms in (model.armature, model.damping, model.friction):  # bar 2 turns with bar 1
        terms[model.idx_vs[bar1]] += terms[model.idx_vs[bar2]]
    platform = closures.frame_id(closures.spec["platform"]["frame"], "platform.frame")
    tips = [closures.frame_id(f"{leg}_tip", "closures") for leg in LEGS] + [platform]
    chains, order = [], []
    for tip, names in zip(tips, CHAIN_JOINTS):
        chain, joints = chain_from_tree(model, tip, closures.slip_speed)
        if [model.names[j] for j in joints] != list(names):
            raise FreefloatError(f"{closures.path}: the chain to frame '{model.frames[tip].name}' has joints "
                                 f"{[model.names[j] for j in joints]}, expected {list(names)}")
        chains.append(chain)
        order += joints
    data = model.createData()
    pin.framesForwardKinematics(model, data, pin.neutral(model))
    if not np.allclose(data.oMf[platform].rotation, np.eye(3), atol=1e-12):
        raise FreefloatError(f"{closures.path}: frame '{model.frames[platform].name}' must be parallel to the inertial "
                             "frame when the parallelogram is closed (zero joint angles)")
    attach = np.array([(data.oMf[platform].inverse() * data.oMf[closures.frame_id(f"platform_a{i}", "closures")]).translation
                       for i in (1, 2)])
    p, n, legs = 3, len(order), 3 * len(LEGS)
    # rows: the RSU tips do not turn (Q, 3 per leg), the coupler stays parallel to the slider (R)
    Q = np.zeros((legs + 1, 3 * len(chains)))
    Q[:legs, :legs] = np.eye(legs)
    R = np.zeros((legs + 1, n))
    R[legs, [order.index(bar1), order.index(model.getJointId("ppap_coupler"))]] = 1.0
    angular = AngularConstraints(P=np.zeros((legs + 1, p)), Q=Q, R=R, reference=np.tile(np.eye(3), (len(chains), 1, 1)),
                                 offset=np.zeros(legs + 1))
    mech = ParallelMechanism(chains=tuple(chains), platform_mass=np.zeros((p, p)), platform_gravity=np.zeros(p),
                             D=np.vstack([np.eye(3)] * 3), d=-np.concatenate((attach[0], attach[1], np.zeros(3))),
                             E=np.eye(9), F=np.zeros((9, n)),
                             actuated=np.array([p + order.index(j) for j in closures.actuated]), angular=angular)
    coordinates = {j: p + i for i, j in enumerate(order)} | {bar2: p + order.index(bar1)}
    return ClosedChain(mech, closures.model, closures.constraints, coordinates, closures.actuated, closures.urdf,
                       friction=closures.friction)


def assembly_guess(data: dict, q_sharp: np.ndarray) -> np.ndarray:
    """Joint coordinates q° (16,), ordered as :data:`CHAIN_JOINTS` (RSU 1, RSU 2, PPaP; rad or m),
    near the assembled pose at platform centre ``q_sharp`` (3,), m, inertial frame:
    the PPaP leg exact (bars tilted up), each crank angle exact (its rod reaches the universal
    joint; of the two solutions, the one nearer the zero angle), the spherical joint pointing
    the rod there, the universal joint undoing the spherical joint's two tilts (Newton corrects
    the rest of the orientation).

    Raises:
        FreefloatError: when a leg cannot reach ``q_sharp``, naming the leg.
    """
    rsu, ppap = data["rsu"], data["ppap"]
    lc, lr = rsu["crank_length"], rsu["rod_length"]
    out = []
    for i, leg in enumerate(LEGS):
        u = np.asarray(q_sharp) + np.asarray(data["platform"]["attach"][i])
        delta = u - np.asarray(rsu["pivot"][i])
        # crank tip s = pivot + lc (c0 cos t + (y x c0) sin t); |u - s| = lr gives
        # (delta . c0) cos t + (delta . y x c0) sin t = k
        c0 = np.asarray(rsu["crank"][i], float)
        c1 = np.cross([0.0, 1.0, 0.0], c0)
        k = (delta @ delta + lc**2 - lr**2) / (2.0 * lc)
        rho, phi = np.hypot(delta @ c0, delta @ c1), np.arctan2(delta @ c1, delta @ c0)
        if abs(k) > rho:
            raise FreefloatError(f"2RSU+PPaP: leg {leg} cannot reach the platform at {np.round(q_sharp, 4).tolist()} m")
        crank = min((phi + s * np.arccos(k / rho) for s in (1.0, -1.0)), key=lambda t: abs(np.angle(np.exp(1j * t))))
        tip = lc * (c0 * np.cos(crank) + c1 * np.sin(crank))
        rod = pin.rpy.rpyToMatrix(0.0, crank, 0.0).T @ (delta - tip) / lr
        s3, s2 = -np.arcsin(rod[1]), np.arctan2(rod[0], rod[2])
        out += [crank, 0.0, s2, s3, -s3, -s2]
    rail = np.asarray(ppap["rail"])
    cos_bar = (q_sharp[0] - rail[0] - ppap["lift_offset"]) / ppap["bar_length"]
    if abs(cos_bar) > 1.0:
        raise FreefloatError(f"2RSU+PPaP: the parallelogram cannot reach x = {q_sharp[0]:.4f} m")
    bar = -np.arccos(cos_bar)
    out += [q_sharp[1] - rail[1], bar, -bar, q_sharp[2] - rail[2] + ppap["bar_length"] * np.sin(bar)]
    return np.array(out)


def reference_path(t: np.ndarray, data: dict, radius: float = 0.03, period: float = 1.0):
    """A closed 3-D platform path about the home pose (a tilted figure of eight), with its first
    two time derivatives: ``q#(t) = home + radius (sin wt, sin 2wt / 2, (1 - cos wt) / 2)``,
    ``w = 2 pi / period``.

    Args:
        t: times (N,), s.

    Returns:
        ``(x, xd, xdd)``: platform centre (N, 3), m, and its rates (N, 3), m/s, m/s^2.
    """
    w = 2.0 * np.pi / period
    s1, c1, s2, c2 = np.sin(w * t), np.cos(w * t), np.sin(2 * w * t), np.cos(2 * w * t)
    x = np.asarray(data["home"]) + radius * np.stack((s1, 0.5 * s2, 0.5 * (1.0 - c1)), axis=-1)
    xd = radius * w * np.stack((c1, c2, 0.5 * s1), axis=-1)
    xdd = radius * w**2 * np.stack((-s1, -2.0 * s2, 0.5 * c1), axis=-1)
    return x, xd, xdd
