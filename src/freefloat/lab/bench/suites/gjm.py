"""``gjm`` suite: the GJM quantities, compiled and numpy, against the Pinocchio floor, by robot size.

On each robot of :mod:`.robots` (free-flyer base, one seeded random state), every time is per call,
best of ``repeats`` in which the compiled rows and their floors take turns (the numpy rows: best
of 5 or 3, fewer calls, up to :data:`NUMPY_MAX_JOINTS` joints), in this process's CPU time
(:data:`CLOCK`), with one BLAS thread but for ``numpy_blas_default``; every figure is also given as a ratio to its Pinocchio
floor, and the part ``growth`` gives each row's exponent p of ``time ~ nv^p`` over the generated
robots (:mod:`.growth`):

- ``compiled``: :func:`freefloat.gjm.compute` (H0, H0m, Hm, H*, J0, Jm, J0E, J*, momenta, body
  kinematics), the compiled core; ``numpy``: the same with ``backend="numpy"`` (the reference);
  ``numpy_blas_default``: numpy with the default BLAS threads.
- ``pinocchio_calls`` (the floor of ``compute``): CRBA + centroidal momentum + joint Jacobians +
  frame placements + one frame Jacobian per end-effector, no post-processing;
  ``pinocchio_same_outputs``: :func:`freefloat.dynamics.reference.reference`, the same quantities
  from those calls mapped to the GJM convention in numpy.
- ``compiled_derivatives`` / ``numpy_derivatives``: :func:`freefloat.gjm.derivatives` (every
  dH/dq_k and the time derivatives); their floor is one ``crba``.
"""

from __future__ import annotations

import tempfile
from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pinocchio as pin
from threadpoolctl import threadpool_limits

from ....dynamics import gjm
from ....dynamics.reference import reference
from ....dynamics.verify import random_configuration
from ....robot.joints import JointCoordinates
from ....robot.robot import Robot
from .drawing import growth_axes, save, subplots
from .growth import CLOCK, exponents
from .robots import ARM_COUNTS, QUICK_ARM_COUNTS, robot_names, robots
from .timing import per_call, side_by_side

#: The numpy reference is timed up to this many joints (its derivatives build n^3 arrays in numpy:
#: 59 ms per call at 64 joints).
NUMPY_MAX_JOINTS = 64
#: Issue 23's aim: ``gjm.compute`` at most this many times its Pinocchio floor.
AIM = 2.0
#: The rows whose growth with nv is fitted.
GROWTH_ROWS = ("compiled", "pinocchio_calls", "compiled_derivatives", "crba")


def settings(quick: bool, repeats: int | None) -> dict:
    """Calls per timing, repeats (best of; default 7, 2 quick) and the arm counts swept."""
    return {"calls": 20 if quick else 500, "repeats": repeats or (2 if quick else 7),
            "arm_counts": QUICK_ARM_COUNTS if quick else ARM_COUNTS, "blas_threads": 1, "clock": CLOCK.__name__,
            "numpy_max_joints": NUMPY_MAX_JOINTS, "aim": AIM}


def measure(settings: dict) -> Iterator[tuple[str, dict]]:
    """One part per robot (:func:`one_robot`), then ``growth``: the exponent of each of
    :data:`GROWTH_ROWS` and of ``compute``'s ratio to its floor over the generated robots."""
    grown = []
    with tempfile.TemporaryDirectory() as folder:
        for name, robot in robots(settings["arm_counts"], Path(folder)):
            row = one_robot(robot, settings["calls"], settings["repeats"], robot.n_joints <= settings["numpy_max_joints"])
            grown += [row] if name.startswith("arms") else []
            yield name, row
    yield "growth", exponents(grown, (*GROWTH_ROWS, "compiled_over_pinocchio_calls"),
                              lambda row, key: {**row["seconds_per_call"], **row["ratios"]}[key])


def one_robot(robot: Robot, calls: int, repeats: int, numpy: bool = True) -> dict:
    """Seconds per call of every row (see the module's docstring; the numpy rows when ``numpy``)
    and the ratios to the floors. The derivatives, n^3 numbers, take fewer calls above 16 joints."""
    rng = np.random.default_rng(0)
    q = random_configuration(robot, rng, JointCoordinates(robot), joint_range=1.0)
    v = rng.normal(size=robot.model.nv)
    model, data = robot.model, robot.model.createData()
    ee = robot.end_effector_frame_ids

    def pinocchio_calls():
        pin.crba(model, data, q)
        pin.computeCentroidalMomentum(model, data, q, v)
        pin.computeJointJacobians(model, data, q)
        pin.updateFramePlacements(model, data)
        for fid in ee:
            pin.getFrameJacobian(model, data, fid, pin.LOCAL_WORLD_ALIGNED)

    slow = max(1, calls // 10)
    gjm.compute(robot, q, v)  # build and cache the structure outside the timing
    times = {"numpy_blas_default": per_call(lambda: gjm.compute(robot, q, v, "numpy"), slow, 5, CLOCK)} if numpy else {}
    with threadpool_limits(limits=1, user_api="blas"):
        if numpy:
            times["numpy"] = per_call(lambda: gjm.compute(robot, q, v, "numpy"), slow, 5, CLOCK)
            times["numpy_derivatives"] = per_call(lambda: gjm.derivatives(robot, q, v, "numpy"), max(1, calls // 50), 3,
                                                  CLOCK)
        times.update(side_by_side({
            "compiled": (lambda: gjm.compute(robot, q, v), calls),
            "pinocchio_calls": (pinocchio_calls, calls),
            "pinocchio_same_outputs": (lambda: reference(robot, q, v, data), calls),
            "compiled_derivatives": (lambda: gjm.derivatives(robot, q, v), max(1, calls * 16 // max(16, robot.n_joints))),
            "crba": (lambda: pin.crba(model, data, q), calls),
        }, repeats, CLOCK))
    floor, crba = times["pinocchio_calls"], times["crba"]
    ratios = {"compiled_over_pinocchio_calls": times["compiled"] / floor,
              "pinocchio_same_outputs_over_pinocchio_calls": times["pinocchio_same_outputs"] / floor,
              "compiled_derivatives_over_crba": times["compiled_derivatives"] / crba}
    if numpy:
        ratios.update({"numpy_over_pinocchio_calls": times["numpy"] / floor,
                       "numpy_blas_default_over_one_thread": times["numpy_blas_default"] / times["numpy"],
                       "numpy_derivatives_over_crba": times["numpy_derivatives"] / crba})
    return {"n_joints": robot.n_joints, "end_effectors": len(ee), "seconds_per_call": times, "ratios": ratios}


def summary(report: dict) -> list[str]:
    """What the command prints: ``compute``'s ratio to its floor per robot against the aim, and
    the growth exponents."""
    names = robot_names(report["settings"]["arm_counts"])
    ratios = ", ".join(f"{n} (nv {report[n]['n_joints'] + 6}) {report[n]['ratios']['compiled_over_pinocchio_calls']:.2f}"
                       for n in names)
    growth = ", ".join(f"{key} {p:.2f}" for key, p in report["growth"].items())
    return [f"gjm: compute / Pinocchio floor {ratios}; aim <= {report['settings']['aim']:g}",
            f"gjm: growth exponent p of time ~ nv^p: {growth}"]


def chart(report: dict, path: Path) -> None:
    """Left: time per call against joints on the generated robots; right: each robot's ratios to
    the Pinocchio floor."""
    names = robot_names(report["settings"]["arm_counts"])
    fig, (left, right) = subplots(1, 2, (12, 4.5))
    growth = [report[name] for name in names if name.startswith("arms")]
    joints = [r["n_joints"] for r in growth]
    for key, style in (("compiled", "o-"), ("numpy", "s--"), ("pinocchio_calls", "k^-"), ("compiled_derivatives", "o-"),
                       ("numpy_derivatives", "s--"), ("crba", "kv:")):
        label = f"{key} (p = {report['growth'][key]:.2f})" if key in report["growth"] else key
        left.plot(joints, [r["seconds_per_call"].get(key, np.nan) * 1e6 for r in growth], style, label=label)
    left.set_yscale("log")
    growth_axes(left, "time per call [us]")
    for i, key in enumerate(("compiled_over_pinocchio_calls", "numpy_over_pinocchio_calls", "compiled_derivatives_over_crba",
                             "numpy_derivatives_over_crba")):
        right.bar(np.arange(len(names)) + 0.2 * i, [report[name]["ratios"].get(key, np.nan) for name in names], 0.2,
                  label=key)
    right.set_xticks(np.arange(len(names)) + 0.3, [f"{name}\nn={report[name]['n_joints']}" for name in names], fontsize=7)
    right.axhline(report["settings"]["aim"], color="k", ls=":", label=f"aim: compute <= {report['settings']['aim']:g}x")
    right.set_yscale("log")
    right.set_ylabel("ratio to the Pinocchio floor")
    right.legend(fontsize=8)
    save(fig, path)
