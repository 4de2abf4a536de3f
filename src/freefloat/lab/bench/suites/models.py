"""``models`` suite: every dynamics model of :data:`freefloat.dynamics.models.MODELS` against
Pinocchio's ABA, by robot size.

On each robot of :mod:`.robots` (free-flyer base, zero gravity, one seeded random state and random
joint torques): the time of one ``acceleration(q, v, tau)`` of each model with the compiled core
(the default) and with ``backend="numpy"`` (the reference), each as a ratio to ``pin.aba`` (the
``exact`` model) measured side by side in this process's CPU time: best of ``repeats`` in which
``pin.aba`` and the compiled models take turns; the numpy rows best of 3, on the robots up to 32 joints only (64 would take
minutes); one BLAS thread. The part ``growth`` gives the exponent p of ``time ~ nv^p`` of
``pin.aba`` and of each compiled model, and of each model's ratio to ``pin.aba``, over the
generated robots (:mod:`.growth`).
"""

from __future__ import annotations

import functools
import tempfile
from collections.abc import Iterator
from pathlib import Path

import numpy as np
from threadpoolctl import threadpool_limits

from ....dynamics.models import MODELS, make_model
from ....dynamics.verify import random_configuration
from ....robot.joints import JointCoordinates
from ....robot.robot import Robot
from .drawing import growth_axes, save, subplots
from .growth import CLOCK, exponents
from .robots import ARM_COUNTS, NAMED, QUICK_ARM_COUNTS, robot_names, robots
from .timing import per_call, side_by_side

#: The hand-built models (every model but Pinocchio's ABA).
GJM_MODELS = tuple(name for name in MODELS if name != "exact")
#: The numpy reference on the generated robots (every model on the URDF robots): two models, up
#: to 32 joints.
NUMPY_ON_ARMS, NUMPY_MAX_JOINTS = ("standard", "momentum_routh"), 32
#: Issue 23's aim: every hand-built model at most this many times ``pin.aba``, up to nv 200.
AIM = 3.0


def settings(quick: bool, repeats: int | None) -> dict:
    """Calls per timing, repeats (best of; default 7, 2 quick) and the arm counts swept."""
    return {"calls": 20 if quick else 500, "repeats": repeats or (2 if quick else 7),
            "arm_counts": QUICK_ARM_COUNTS if quick else ARM_COUNTS, "blas_threads": 1, "clock": CLOCK.__name__, "aim": AIM}


def measure(settings: dict) -> Iterator[tuple[str, dict]]:
    """One part per robot (:func:`one_robot`), then ``growth``: the exponents of ``pin.aba``
    (``aba``) and of every compiled model, of its time (``time``) and of its ratio to ``pin.aba``
    (``over_aba``), over the generated robots."""
    grown = []
    with tempfile.TemporaryDirectory() as folder, threadpool_limits(limits=1, user_api="blas"):
        for name, robot in robots(settings["arm_counts"], Path(folder)):
            numpy_models = GJM_MODELS if name in NAMED else NUMPY_ON_ARMS if robot.n_joints <= NUMPY_MAX_JOINTS else ()
            row = one_robot(robot, settings["calls"], settings["repeats"], numpy_models)
            grown += [row] if name.startswith("arms") else []
            yield name, row
    yield "growth", {"aba": exponents(grown, ["aba"], lambda row, _: row["aba_s"])["aba"],
                     "time": exponents(grown, GJM_MODELS, lambda row, model: row["compiled_s"][model]),
                     "over_aba": exponents(grown, GJM_MODELS, lambda row, model: row["compiled_over_aba"][model])}


def one_robot(robot: Robot, calls: int, repeats: int, numpy_models: tuple[str, ...]) -> dict:
    """``pin.aba``'s time per call (s), each compiled model's and each of ``numpy_models``' numpy
    reference's, and their ratios to ``pin.aba``."""
    robot.model.gravity.linear[:] = 0.0
    rng = np.random.default_rng(0)
    q = random_configuration(robot, rng, JointCoordinates(robot), joint_range=1.0)
    v = rng.normal(size=robot.model.nv)
    tau = np.concatenate((np.zeros(robot.n_base), rng.normal(size=robot.n_joints)))
    models = {name: make_model(name, robot) for name in ("exact", *GJM_MODELS)}
    compiled = side_by_side({name: (functools.partial(m.acceleration, q, v, tau), calls) for name, m in models.items()},
                            repeats, CLOCK)
    floor, numpy = compiled.pop("exact"), {}
    for name in numpy_models:
        numpy[name] = per_call(functools.partial(make_model(name, robot, backend="numpy").acceleration, q, v, tau),
                               max(1, calls // 100), 3, CLOCK)
    return {
        "n_joints": robot.n_joints, "aba_s": floor, "compiled_s": compiled, "numpy_s": numpy,
        "compiled_over_aba": {k: t / floor for k, t in compiled.items()},
        "numpy_over_aba": {k: t / floor for k, t in numpy.items()},
    }


def summary(report: dict) -> list[str]:
    """What the command prints: the dearest model's ratio to ``pin.aba`` per robot against the
    aim, and the growth exponents."""
    names = robot_names(report["settings"]["arm_counts"])
    worst = ", ".join(f"{n} (nv {report[n]['n_joints'] + 6}) {max(report[n]['compiled_over_aba'].values()):.2f}"
                      for n in names)
    growth = report["growth"]
    models = ", ".join(f"{m} {p:.2f}" for m, p in growth["time"].items())
    return [f"models: dearest model / pin.aba {worst}; aim <= {report['settings']['aim']:g}",
            f"models: growth exponent p of time ~ nv^p: pin.aba {growth['aba']:.2f}; {models}"]


def chart(report: dict, path: Path) -> None:
    """Left: each model's ratio to ``pin.aba`` on the first robot, compiled and numpy; right: the
    compiled ratio against joints on the generated robots."""
    names = robot_names(report["settings"]["arm_counts"])
    fig, (left, right) = subplots(1, 2, (13, 4.5))
    first = report[names[0]]
    x = np.arange(len(GJM_MODELS))
    left.bar(x - 0.2, [first["compiled_over_aba"][m] for m in GJM_MODELS], 0.4, label="compiled")
    left.bar(x + 0.2, [first["numpy_over_aba"].get(m, np.nan) for m in GJM_MODELS], 0.4, label="numpy (reference)")
    left.axhline(report["settings"]["aim"], color="k", ls=":", label=f"aim: {report['settings']['aim']:g}x aba")
    left.set_xticks(x, GJM_MODELS, rotation=45, ha="right", fontsize=8)
    left.set_yscale("log")
    left.set_ylabel("time per acceleration / pin.aba")
    left.set_title(f"{names[0]} (n = {first['n_joints']})")
    left.legend(fontsize=8)
    growth = [report[name] for name in names if name.startswith("arms")]
    for model in GJM_MODELS:
        right.plot([r["n_joints"] for r in growth], [r["compiled_over_aba"][model] for r in growth], "o-",
                   label=f"{model} (time ~ nv^{report['growth']['time'][model]:.2f})")
    right.axhline(report["settings"]["aim"], color="k", ls=":",
                  label=f"aim; pin.aba ~ nv^{report['growth']['aba']:.2f}")
    growth_axes(right, "compiled time / pin.aba")
    save(fig, path)
