"""Fuzz class of Python API calls (issue 24): the public functions called with arguments of the
wrong shape, type or size, not finite, or huge. Each call must return a finite result or raise
one of freefloat's errors (a subclass of ``FreefloatError``) naming the problem: another
exception is a ``traceback``, a NaN or infinity in what it returns is ``non-finite``, an
argument that is plainly wrong but accepted is ``accepted``, a call past the time bound a ``hang``.
"""

from __future__ import annotations

import contextlib
import functools
import os
import random
import resource
import signal
import warnings
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from .fuzzing import TIME_BOUND


#: Wrong values for an array argument of ``n`` numbers: (what, value, plainly wrong).
def _bad_arrays(n: int) -> list[tuple[str, Any, bool]]:
    return [("one short", np.zeros(n - 1), True), ("one long", np.zeros(n + 1), True),
            ("2-D", np.zeros((n, 2)), True), ("empty", np.zeros(0), True), ("a scalar", 0.0, True),
            ("NaN", np.full(n, np.nan), True), ("inf", np.full(n, np.inf), True), ("strings", ["a"] * n, True),
            ("None", None, True), ("complex", np.zeros(n, dtype=complex) + 1j, True),
            ("a list", [0.0] * n, False), ("ints", np.zeros(n, dtype=int), False),
            ("huge", np.full(n, 1e300), False), ("10**8 long", np.broadcast_to(0.0, (10**8,)), True)]


BAD_NUMBERS = [("NaN", float("nan"), True), ("inf", float("inf"), True), ("negative", -1.0, True),
               ("zero", 0.0, True), ("a string", "1", True), ("None", None, True), ("huge", 1e300, True),
               ("10**12", 10**12, False), ("tiny", 1e-300, True)]


@functools.cache
def _robot():
    """The two-arm planar robot (free base), loaded once per process."""
    from freefloat import load_robot
    from freefloat.paths import URDF_DIR

    return load_robot(URDF_DIR / "two_arm_planar.urdf", visuals=False)


def _acceleration(rng: random.Random):
    from freefloat import MODELS, make_model

    robot, name = _robot(), rng.choice(list(MODELS))
    args = {"q": robot.neutral(), "v": np.zeros(robot.model.nv), "tau": np.zeros(robot.model.nv)}
    which = rng.choice(sorted(args))
    what, value, wrong = rng.choice(_bad_arrays(len(args[which])))
    args[which] = value
    return f"make_model('{name}').acceleration({which}: {what})", wrong, \
        lambda: make_model(name, robot).acceleration(**args)


def _run(rng: random.Random):
    from freefloat import make_integrator, make_model, run

    robot = _robot()
    args = {"q0": robot.neutral(), "v0": np.zeros(robot.model.nv), "duration": 0.01, "control_period": 0.001,
            "record_every": 1}
    which = rng.choice(sorted(args))
    if which in ("q0", "v0"):
        what, value, wrong = rng.choice(_bad_arrays(len(args[which])))
    else:
        what, value, wrong = rng.choice(BAD_NUMBERS + [("1e9", 1e9, which != "record_every")])
        wrong = wrong and not (which == "record_every" and what in ("huge", "10**12", "1e9"))
    args[which] = value
    return f"run({which}: {what})", wrong, lambda: run(
        robot, args["q0"], args["v0"], args["duration"], args["control_period"],
        make_integrator("rkmk4", robot.model), make_model("exact", robot), record_every=args["record_every"])


def _factories(rng: random.Random):
    from freefloat import load_robot, make_integrator, make_model
    from freefloat.paths import URDF_DIR

    robot, urdf = _robot(), URDF_DIR / "two_arm_planar.urdf"
    what, value, wrong = rng.choice(BAD_NUMBERS + [("a name", "nosuch", True), ("3 numbers", (0.0, 0.0, -9.81), False)])
    calls = {
        "make_model(name)": lambda: make_model(value, robot),
        "make_integrator(name)": lambda: make_integrator(value, robot.model),
        "make_integrator(substeps)": lambda: make_integrator("rkmk4", robot.model, substeps=value),
        "make_integrator(rtol)": lambda: make_integrator("dopri5", robot.model, rtol=value),
        "load_robot(gravity)": lambda: load_robot(urdf, gravity=value, visuals=False),
        "load_robot(base)": lambda: load_robot(urdf, base=value, visuals=False),
        "load_robot(path)": lambda: load_robot(value),
    }
    call = rng.choice(sorted(calls))
    wrong = wrong or what == "3 numbers" and "gravity" not in call
    return f"{call}: {what}", wrong, calls[call]


def _checks(rng: random.Random):
    from freefloat import QuinticTrajectory, check_robot

    robot = _robot()
    what, value, wrong = rng.choice(BAD_NUMBERS)
    n = robot.n_joints
    calls = {
        "check_robot(samples)": lambda: check_robot(robot, samples=value),
        "check_robot(seed)": lambda: check_robot(robot, samples=1, seed=value),
        "QuinticTrajectory(duration)": lambda: QuinticTrajectory(np.zeros(n), np.ones(n), value),
        "QuinticTrajectory(goal)": lambda: QuinticTrajectory(np.zeros(n), np.full(n, value), 1.0),
    }
    call = rng.choice(sorted(calls))
    wrong = wrong and not (call == "check_robot(seed)" and what in ("huge", "10**12", "zero"))
    wrong = wrong and not (call == "QuinticTrajectory(goal)" and what in ("negative", "zero", "tiny"))
    return f"{call}: {what}", wrong, calls[call]


def _telemetry_files(rng: random.Random):
    from freefloat import Telemetry

    kind = rng.choice(["cut", "flipped", "random", "pickled", "empty", "folder", "missing"])
    cut, flip, noise = rng.random(), rng.random(), rng.randbytes(rng.randrange(1, 2000))

    def load(folder: Path):
        good = folder / "good.npz"
        Telemetry.allocate(3, _robot().model.nq, _robot().model.nv, 2, 1).save(good)
        data, path = good.read_bytes(), folder / f"{kind}.npz"
        if kind == "cut":
            path.write_bytes(data[: int(cut * len(data))])
        elif kind == "flipped":  # a byte of the zip's dates may flip unnoticed: either outcome is fine
            at = int(flip * len(data))
            path.write_bytes(data[:at] + bytes([data[at] ^ 0xFF]) + data[at + 1:])
        elif kind == "random":
            path.write_bytes(noise)
        elif kind == "pickled":
            np.savez(path, t=np.array([object()], dtype=object))
        elif kind == "empty":
            path.write_bytes(b"")
        elif kind == "folder":
            path.mkdir()
        return Telemetry.load(path)

    return f"Telemetry.load(a {kind} file)", kind != "flipped", load


#: What a caller might hand where an object or a path belongs (issue 41).
NOT_OBJECTS = [("None", None), ("a string", "nosuch"), ("a dict", {"a": 1}), ("a number", 3)]


def _objects(rng: random.Random):
    from freefloat import make_integrator, make_model, run, simulate

    robot = _robot()
    what, value = rng.choice(NOT_OBJECTS)
    start = (robot.neutral(), np.zeros(robot.model.nv), 0.01, 0.001)
    calls = {
        "make_integrator(model)": lambda: make_integrator("rkmk4", value),
        "make_model(robot)": lambda: make_model("exact", value),
        "run(system)": lambda: run(value, *start),
        "run(integrator)": lambda: run(robot, *start, integrator=value),
        "run(model)": lambda: run(robot, *start, model=value),
        "run(controller)": lambda: run(robot, *start, controller=value),
        "simulate(scene)": lambda: simulate(value),
    }
    call = rng.choice(sorted(calls))
    wrong = not (call in ("run(model)", "run(controller)") and what == "None")  # None: their defaults
    return f"{call}: {what}", wrong and not (call == "simulate(scene)" and what == "a string"), calls[call]


def _gain_design(rng: random.Random):
    from dataclasses import replace

    from freefloat.parallel.five_bar import FiveBarParameters, five_bar
    from freefloat.parallel.sliding_mode import design_gains

    what, value, wrong = rng.choice(BAD_NUMBERS)
    point = np.array([[0.0, 0.2]])
    calls = {
        "design_gains(eta)": lambda: design_gains(FiveBarParameters(), point, eta=value),
        "design_gains(points: one flat)": lambda: design_gains(FiveBarParameters(), [0.0, 0.2]),
        "design_gains(uncertainty: a key)": lambda: design_gains(FiveBarParameters(), point, uncertainty={"l11": 0.01}),
        "design_gains(uncertainty: a width)": lambda: design_gains(FiveBarParameters(), point, uncertainty={"l1": value}),
        "five_bar(l1)": lambda: five_bar(replace(FiveBarParameters(), l1=value)),
    }
    call = rng.choice(sorted(calls))
    if call.startswith("design_gains(points") or call.endswith("a key)"):
        wrong = True
    elif call.endswith("a width)") or call == "five_bar(l1)":
        wrong = wrong and what not in ("huge", "10**12", "tiny") or (call == "five_bar(l1)" and what == "zero")
        wrong = wrong and not (call.endswith("a width)") and what == "zero")
    return f"{call}: {what}", wrong, calls[call]


MAKERS: list[Callable[[random.Random], tuple[str, bool, Callable]]] = [
    _acceleration, _acceleration, _run, _run, _factories, _checks, _telemetry_files, _objects, _gain_design]


@dataclass
class ApiCase:
    """One call of the public API with a hostile argument."""

    seed: int
    kind: str = "api"

    @property
    def mutation(self) -> str:
        return self._call()[0]

    def _call(self):
        rng = random.Random(self.seed)
        return rng.choice(MAKERS)(rng)

    def run(self, folder: Path) -> tuple[str, str]:
        """Make the call in this process within the time bound: its outcome and detail."""
        from freefloat import FreefloatError

        folder.mkdir(parents=True, exist_ok=True)
        what, wrong, call = self._call()

        def expire(signum, frame):
            raise TimeoutError

        previous = signal.signal(signal.SIGALRM, expire)
        signal.setitimer(signal.ITIMER_REAL, TIME_BOUND)
        try:
            with warnings.catch_warnings(), np.errstate(all="ignore"), _memory_cap():
                warnings.simplefilter("ignore")
                result = call(folder) if what.startswith("Telemetry.load") else call()
        except TimeoutError:
            return "hang", f"over {TIME_BOUND:g} s"
        except FreefloatError as exc:
            return "refused", f"{type(exc).__name__}: {exc}"[:300]
        except BaseException as exc:  # noqa: BLE001 - anything else escaping is the failure looked for
            return "traceback", f"{type(exc).__name__}: {exc}"[:300]
        finally:
            signal.setitimer(signal.ITIMER_REAL, 0)
            signal.signal(signal.SIGALRM, previous)
        if not _finite(result):
            return "non-finite", f"{what} returned a NaN or infinity"
        return ("accepted", f"{what} returned a result") if wrong else ("completed", "")


@contextlib.contextmanager
def _memory_cap(extra: float = 2e9):
    """At most ``extra`` more bytes of address space inside the block (a call that tries to
    allocate its huge argument gets a MemoryError, not the shared machine's memory)."""
    soft, hard = resource.getrlimit(resource.RLIMIT_AS)
    size = int(Path("/proc/self/statm").read_text().split()[0]) * os.sysconf("SC_PAGE_SIZE")
    cap = size + int(extra) if hard == resource.RLIM_INFINITY else min(size + int(extra), hard)
    resource.setrlimit(resource.RLIMIT_AS, (cap, hard))
    try:
        yield
    finally:
        resource.setrlimit(resource.RLIMIT_AS, (soft, hard))


def _finite(result: object) -> bool:
    """Whether every number a call returned (an array, a run's telemetry) is finite."""
    telemetry = getattr(result, "telemetry", None)
    if telemetry is not None:
        return all(np.isfinite(np.asarray(getattr(telemetry, name), dtype=float)).all()
                   for name in ("t", "q", "v") if hasattr(telemetry, name))
    if isinstance(result, np.ndarray) and result.dtype.kind in "fc":
        return bool(np.isfinite(result).all())
    return True


def api_case(seed: int) -> ApiCase:
    """A call of the public API with one hostile argument (:data:`MAKERS`)."""
    return ApiCase(seed)
