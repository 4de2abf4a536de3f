"""``kernel`` suite: freefloat's dynamics kernel (``cpp/kernel``, :mod:`freefloat.dynamics.kernel`)
against Pinocchio's ABA and MuJoCo, per evaluation, per step and per batch, side by side in one
process.

The robots: the dual-arm satellite (nv 18), the four-arm robot (nv 22) and 32 and 48 spatial
4-link arms around one base (nv 134, 198), free-flying, zero gravity; the four-arm robot's inertias
balanced (MuJoCo refuses the URDF's) on every side. Each robot is written as MJCF for MuJoCo
(:mod:`..mjcf`: contacts, constraints and energy off). Random states (joint angles within +-1 rad,
rates within +-0.3 rad/s), random joint torques for the evaluations, torque-free steps.

Parts, one per robot and measure, the methods taking turns within each of ``repeats`` rounds
(best of rounds), timed in CPU time (this process's, or in C++ the calling thread's: the machine
is shared, and other processes' load inflates the wall clock), with one BLAS thread:

- ``evaluation``: seconds per forward-dynamics evaluation. In C++, timed there over ``calls``
  calls with no Python between them: Pinocchio's ``aba`` as the compiled loop calls it (WORLD
  convention, ``libpinocchio_default``), the kernel for one state, the kernel's lockstep per state
  (four states a call), both also in the baseline instruction set; MuJoCo's ``mj_step`` with its
  Euler integrator inside ``mujoco.rollout`` (one ``mj_forward`` and an Euler update per step, in
  C). From Python, one call each: ``pin.aba``, the kernel's ``Kernel.aba`` and ``mujoco.mj_forward``
  (each with about a microsecond of binding).
- ``step``: seconds per 1 ms step of a torque-free run, telemetry at the ends only: freefloat's
  compiled loop (RKMK4, one call for the whole run) on Pinocchio's ABA and on the kernel, four runs
  in lockstep (``run_many`` over :data:`LOCKSTEP_STEPS` times as many steps, per run and step, the
  best one-step call's time taken from the best call's: at nv 198 the call's own Python, the four
  loops' set-up and checks, is about 13 ms of CPU), and MuJoCo's RK4 in ``mujoco.rollout``.
- ``batch``: ``N`` runs (16 and 256) of ``duration`` s at 1 ms on one thread, each from its own
  state, as runs per second: ``run_many`` in lockstep and one run at a time (telemetry at the ends;
  and in lockstep with a telemetry row every step), and ``mujoco.rollout`` on one thread returning
  every step's state. Ratios are freefloat's rate over MuJoCo's.

The floor of every freefloat number is C++ (the kernel or Pinocchio's ``aba``) with no Python
between periods; MuJoCo's rollout numbers are C with no Python between steps; the "Python call"
numbers add each binding's own call cost.
"""

from __future__ import annotations

import tempfile
import time
import warnings
from collections.abc import Iterator
from dataclasses import replace
from pathlib import Path

import numpy as np
import pinocchio as pin
from threadpoolctl import threadpool_limits

from ....dynamics import kernel
from ....dynamics.compiled import CompiledLoop
from ....dynamics.integrators import make_integrator
from ....dynamics.kernel import LANES, Kernel
from ....dynamics.many_runs import run_many
from ....dynamics.models import ExactModel
from ....dynamics.telemetry import Telemetry
from ....dynamics.verify import random_configuration
from ....robot.joints import JointCoordinates
from ....robot.robot import Robot
from ..in_mujoco.mjcf import balanced_model, mjcf_from_model
from ..in_mujoco.state import to_mujoco
from .drawing import save, subplots
from .robots import robots

#: The generated robots swept besides the named ones: 32 and 48 arms (nv 134, 198).
ARM_COUNTS, QUICK_ARM_COUNTS = (32, 48), ()
#: The batches' sizes (runs on one thread), full and quick.
BATCHES, QUICK_BATCHES = (16, 256), (4, 16)
#: The issue's aims (issue 40): batch runs per core over mujoco.rollout's in process, N = 256.
AIMS = {"batch_in_process_over_rollout": 2.5}
#: Evaluation methods in C++ (the first the reference of the ratios) and from Python.
CPP = ("pinocchio", "kernel", "kernel lanes", "kernel baseline", "kernel lanes baseline", "mujoco mj_step euler")
PYTHON = ("pin.aba", "Kernel.aba", "mj_forward")
STEPS = ("loop pinocchio", "loop kernel", "lockstep", "mujoco rk4")
#: The lockstep's step is timed over this many times the other ways' steps (a call's own cost, a
#: one-step call's, taken out: 13 ms of CPU at nv 198 against 4 x 35 us a step).
LOCKSTEP_STEPS = 5
BATCH_WAYS = ("lockstep", "one at a time", "lockstep, every row", "mujoco.rollout")


def settings(quick: bool, repeats: int | None) -> dict:
    """Rounds (default 7; 2 quick), evaluations per timing, steps per step timing, batch sizes and
    durations (1 s up to nv 30, 0.2 s above; 0.05 s quick), the instruction set, the aims."""
    return {"repeats": repeats or (2 if quick else 7), "batch_repeats": repeats or (1 if quick else 3),
            "calls": 200 if quick else 20000, "steps": 100 if quick else 1000,
            "arm_counts": QUICK_ARM_COUNTS if quick else ARM_COUNTS, "batches": QUICK_BATCHES if quick else BATCHES,
            "batch_duration_s": {"nv <= 30": 0.05 if quick else 1.0, "nv > 30": 0.05 if quick else 0.2},
            "control_period_s": 1e-3, "threads": 1, "isa": kernel.isa(), "lanes": LANES, "aims": AIMS}


def measure(settings: dict) -> Iterator[tuple[str, dict]]:
    """Per robot: ``evaluation/<robot>``, ``step/<robot>``, ``batch/<robot>``."""
    with tempfile.TemporaryDirectory() as folder, warnings.catch_warnings(), threadpool_limits(limits=1, user_api="blas"):
        warnings.simplefilter("ignore")  # the balanced inertias' warning, once per robot
        for name, loaded in robots(settings["arm_counts"], Path(folder)):
            robot = replace(loaded, model=balanced_model(loaded.model))
            robot.model.gravity.linear[:] = 0.0
            setup = Setup(robot, name)
            yield f"evaluation/{name}", evaluation(setup, settings)
            yield f"step/{name}", step(setup, settings)
            yield f"batch/{name}", batch(setup, settings)


class Setup:
    """One robot on both sides: the freefloat robot, its MuJoCo model, and seeded states."""

    def __init__(self, robot: Robot, name: str):
        import mujoco

        self.robot, self.name, self.nv = robot, name, robot.model.nv
        self.plant = ExactModel(robot)  # its Data: 0.4 s at nv 198, made once
        self.mujoco = mujoco.MjModel.from_xml_string(mjcf_from_model(robot.model, name, 1e-3, "RK4", energy=False))
        self.euler = mujoco.MjModel.from_xml_string(mjcf_from_model(robot.model, name, 1e-3, "Euler", energy=False))

    def states(self, count: int, seed: int) -> tuple[np.ndarray, np.ndarray]:
        """``count`` Pinocchio states (count, nq), (count, nv): joints within +-1 rad, rates +-0.3."""
        rng = np.random.default_rng(seed)
        coordinates = JointCoordinates(self.robot)
        q = np.array([random_configuration(self.robot, rng, coordinates, joint_range=1.0) for _ in range(count)])
        return q, rng.uniform(-0.3, 0.3, (count, self.nv))

    def mujoco_states(self, model, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        """MuJoCo's full physics states (count, nstate) of Pinocchio's ``q``, ``v``."""
        import mujoco

        data, spec = mujoco.MjData(model), mujoco.mjtState.mjSTATE_FULLPHYSICS
        out = np.zeros((len(q), mujoco.mj_stateSize(model, spec)))
        for i, (qi, vi) in enumerate(zip(q, v)):
            data.qpos[:], data.qvel[:] = to_mujoco(qi, vi)
            mujoco.mj_getState(model, data, out[i], spec)
        return out


def best_of(methods: dict, repeats: int) -> dict[str, float]:
    """``{name: fn() -> seconds}`` called in turn ``repeats`` times: the least of each."""
    best = dict.fromkeys(methods, np.inf)
    for _ in range(repeats):
        for name, fn in methods.items():
            best[name] = min(best[name], fn())
    return best


#: The clock of every timing made in Python: this process's CPU time (its C++ threads' included).
CLOCK = time.process_time


def python_call(fn, calls: int) -> float:
    """Seconds per ``fn()`` over ``calls`` calls from Python."""
    start = CLOCK()
    for _ in range(calls):
        fn()
    return (CLOCK() - start) / calls


def with_isa(isa: str, fn):
    """``fn`` run with the kernel evaluating in ``isa`` (the default restored after)."""
    def call() -> float:
        default = kernel.isa()
        kernel.set_isa(isa)
        try:
            return fn()
        finally:
            kernel.set_isa(default)
    return call


def evaluation(setup: Setup, settings: dict) -> dict:
    """Seconds per evaluation of each method (see the module docstring), and each over Pinocchio's
    C++ ``aba`` and over MuJoCo's ``mj_step`` (Euler)."""
    import mujoco
    from mujoco import rollout

    robot, calls = setup.robot, max(50, settings["calls"] * 22 // setup.nv)
    model, rng = robot.model, np.random.default_rng(1)
    q, v = (x[0] for x in setup.states(1, 0))
    tau = np.r_[np.zeros(robot.n_base), rng.normal(size=robot.n_joints)]
    loop = CompiledLoop(robot, make_integrator("rkmk4", model), 1e-3)
    k, data = Kernel(model), model.createData()
    lanes = (np.array([q] * LANES), np.array([v] * LANES), np.array([tau] * LANES))
    mj_data = mujoco.MjData(setup.mujoco)
    mj_data.qpos[:], mj_data.qvel[:] = to_mujoco(q, v)
    mj_data.qfrc_applied[:] = tau  # joint rows as Pinocchio's; the base's zero
    euler, euler_data = rollout.Rollout(nthread=0), mujoco.MjData(setup.euler)
    initial = setup.mujoco_states(setup.euler, q[None], v[None])
    steps = max(10, calls // 10)

    def loop_aba(kind: str):
        def call() -> float:
            loop.sim.tree_aba = kind
            return loop.sim.time_acceleration(q, v, tau, calls)
        return call

    def mujoco_euler() -> float:
        start = CLOCK()
        euler.rollout(setup.euler, [euler_data], initial, nstep=steps)
        return (CLOCK() - start) / steps

    methods = {
        "pinocchio": loop_aba("pinocchio"), "kernel": loop_aba("kernel"),
        "kernel lanes": lambda: k.time_aba_lanes(*lanes, calls) / LANES,
        "kernel baseline": with_isa("baseline", lambda: k.time_aba(q, v, tau, calls)),
        "kernel lanes baseline": with_isa("baseline", lambda: k.time_aba_lanes(*lanes, calls) / LANES),
        "mujoco mj_step euler": mujoco_euler,
        "pin.aba": lambda: python_call(lambda: pin.aba(model, data, q, v, tau), calls),
        "Kernel.aba": lambda: python_call(lambda: k.aba(q, v, tau), calls),
        "mj_forward": lambda: python_call(lambda: mujoco.mj_forward(setup.mujoco, mj_data), calls),
    }
    best = best_of(methods, settings["repeats"])
    euler.close()
    return {"nv": setup.nv, "calls": calls, "seconds": best,
            "over_pinocchio": {name: t / best["pinocchio"] for name, t in best.items()},
            "over_mujoco": {name: t / best["mujoco mj_step euler"] for name, t in best.items()}}


def step(setup: Setup, settings: dict) -> dict:
    """Seconds per 1 ms step of each way (see the module docstring) and each over MuJoCo's RK4."""
    import mujoco
    from mujoco import rollout

    robot, steps, dt = setup.robot, max(20, settings["steps"] * 22 // setup.nv), settings["control_period_s"]
    model, integrator = robot.model, make_integrator("rkmk4", robot.model)
    q0, v0 = setup.states(LANES, 2)
    loops, chunk = {}, Telemetry.allocate(2, model.nq, model.nv, robot.n_joints, len(robot.end_effectors))
    for kind in ("pinocchio", "kernel"):
        loops[kind] = CompiledLoop(robot, integrator, dt, record_every=steps)
        loops[kind].sim.tree_aba = kind
    pool, data = rollout.Rollout(nthread=0), mujoco.MjData(setup.mujoco)
    initial = setup.mujoco_states(setup.mujoco, q0[:1], v0[:1])

    def loop_steps(loop):
        def call() -> float:
            loop.start(q0[0], v0[0])
            start = CLOCK()
            loop.run(steps, chunk, 0)
            return (CLOCK() - start) / steps
        return call

    def lockstep_call(periods: int):
        def call() -> float:
            start = CLOCK()
            run_many(robot, q0, v0, periods * dt, dt, integrator, setup.plant, record_every=periods, keep=False,
                     lockstep=True)
            return CLOCK() - start
        return call

    def mujoco_rk4() -> float:
        start = CLOCK()
        pool.rollout(setup.mujoco, [data], initial, nstep=steps)
        return (CLOCK() - start) / steps

    long = LOCKSTEP_STEPS * steps
    lockstep_call(1)()  # the lanes' loops made and kept, outside the clock
    best = best_of({"loop pinocchio": loop_steps(loops["pinocchio"]), "loop kernel": loop_steps(loops["kernel"]),
                    "lockstep call": lockstep_call(long + 1), "lockstep call, one step": lockstep_call(1),
                    "mujoco rk4": mujoco_rk4}, settings["repeats"])
    pool.close()
    calls = {"periods": long + 1, "seconds": best.pop("lockstep call"), "one_step_seconds": best.pop("lockstep call, one step")}
    best["lockstep"] = (calls["seconds"] - calls["one_step_seconds"]) / (long * LANES)  # the call's own cost out
    return {"nv": setup.nv, "steps": steps, "seconds": {way: best[way] for way in STEPS}, "lockstep_calls": calls,
            "over_mujoco": {way: best[way] / best["mujoco rk4"] for way in STEPS}}


def batch(setup: Setup, settings: dict) -> dict:
    """Per batch size: seconds per batch and runs per second of each way, and each rate over
    ``mujoco.rollout``'s (see the module docstring)."""
    import mujoco
    from mujoco import rollout

    robot, dt = setup.robot, settings["control_period_s"]
    duration = settings["batch_duration_s"]["nv <= 30" if setup.nv <= 30 else "nv > 30"]
    steps, integrator = round(duration / dt), make_integrator("rkmk4", robot.model)
    out = {"nv": setup.nv, "duration_s": duration, "steps": steps}
    pool, data = rollout.Rollout(nthread=0), mujoco.MjData(setup.mujoco)
    for runs in settings["batches"]:
        q0, v0 = setup.states(runs, 3)
        initial = setup.mujoco_states(setup.mujoco, q0, v0)

        def freefloat(lockstep: bool, every: int):
            def call() -> float:
                start = CLOCK()
                run_many(robot, q0, v0, duration, dt, integrator, setup.plant, record_every=every, keep=False,
                         lockstep=lockstep)
                return CLOCK() - start
            return call

        def mujoco_rollout() -> float:
            start = CLOCK()
            pool.rollout(setup.mujoco, [data], initial, nstep=steps)
            return CLOCK() - start

        ways = {"lockstep": freefloat(True, steps), "one at a time": freefloat(False, steps),
                "lockstep, every row": freefloat(True, 1), "mujoco.rollout": mujoco_rollout}
        for way in ways.values():  # loops made and kept, pools started, outside the clock
            way()
        best = best_of(ways, settings["batch_repeats"])
        rate = {name: runs / t for name, t in best.items()}
        out[str(runs)] = {"seconds": best, "runs_per_second": rate,
                          "over_rollout": {name: r / rate["mujoco.rollout"] for name, r in rate.items()}}
    pool.close()
    return out


def parts(report: dict, kind: str) -> dict[str, dict]:
    """The parts of ``kind`` (``evaluation``, ``step``, ``batch``) by robot name."""
    return {key.split("/", 1)[1]: value for key, value in report.items() if key.startswith(kind + "/")}


def summary(report: dict) -> list[str]:
    """Per robot: the kernel's and its lanes' evaluation over Pinocchio's and MuJoCo's, the steps
    over MuJoCo's RK4, the batches over mujoco.rollout."""
    lines = []
    steps, batches = parts(report, "step"), parts(report, "batch")
    for name, row in parts(report, "evaluation").items():
        p, m = row["over_pinocchio"], row["over_mujoco"]
        line = (f"kernel: {name} (nv {row['nv']}): evaluation over pin C++ aba: kernel {p['kernel']:.2f}, lanes "
                f"{p['kernel lanes']:.2f}; over MuJoCo's Euler step: kernel {m['kernel']:.2f}, lanes "
                f"{m['kernel lanes']:.2f}")
        if name in steps:
            s = steps[name]["over_mujoco"]
            line += f"; RK4 step over MuJoCo's: loop {s['loop kernel']:.2f}, lockstep {s['lockstep']:.2f}"
        for runs in report["settings"]["batches"]:
            if name in batches and str(runs) in batches[name]:
                b = batches[name][str(runs)]["over_rollout"]
                line += f"; N={runs} runs/s over rollout: lockstep {b['lockstep']:.2f}, one at a time {b['one at a time']:.2f}"
        lines.append(line)
    return lines


def chart(report: dict, path: Path) -> None:
    """Left: seconds per evaluation per robot and method (log scale); middle: seconds per step;
    right: batch runs per second over mujoco.rollout's, per robot and batch size."""
    evaluations, steps, batches = parts(report, "evaluation"), parts(report, "step"), parts(report, "batch")
    names = list(evaluations)
    fig, (left, middle, right) = subplots(1, 3, (17, 4.8))
    shown = ("pinocchio", "kernel", "kernel lanes", "mujoco mj_step euler", "pin.aba", "mj_forward")
    width = 0.8 / len(shown)
    for j, method in enumerate(shown):
        left.bar([i + j * width for i in range(len(names))], [evaluations[n]["seconds"][method] * 1e6 for n in names],
                 width, label=method)
    left.set_xticks([i + 0.4 - width / 2 for i in range(len(names))],
                    [f"{n}\nnv {evaluations[n]['nv']}" for n in names], fontsize=8)
    left.set_yscale("log")
    left.set_ylabel("us per evaluation (best of rounds)")
    left.set_title("forward dynamics: C++ (first four) and a Python call (last two)")
    left.legend(fontsize=7)
    width = 0.8 / len(STEPS)
    for j, way in enumerate(STEPS):
        middle.bar([i + j * width for i in range(len(names))], [steps[n]["seconds"][way] * 1e6 for n in names], width,
                   label=way)
    middle.set_xticks([i + 0.4 - width / 2 for i in range(len(names))], names, fontsize=8)
    middle.set_yscale("log")
    middle.set_ylabel("us per 1 ms step (per run)")
    middle.set_title("RKMK4 (freefloat) and RK4 (MuJoCo) steps, telemetry at the ends")
    middle.legend(fontsize=7)
    sizes = report["settings"]["batches"]
    ways = BATCH_WAYS[:-1]
    width = 0.8 / (len(ways) * len(sizes))
    for j, (runs, way) in enumerate((r, w) for r in sizes for w in ways):
        right.bar([i + j * width for i in range(len(names))],
                  [batches[n][str(runs)]["over_rollout"][way] for n in names], width, label=f"N={runs}, {way}")
    right.axhline(1.0, color="k", lw=0.8)
    right.axhline(AIMS["batch_in_process_over_rollout"], color="grey", ls=":",
                  label=f"aim {AIMS['batch_in_process_over_rollout']}x (N=256)")
    right.set_xticks([i + 0.4 - width / 2 for i in range(len(names))], names, fontsize=8)
    right.set_ylim(0.0, 1.4 * max(batches[n][str(r)]["over_rollout"][w] for n in names for r in sizes for w in ways))
    right.set_ylabel("runs/s over mujoco.rollout (one thread)")
    right.set_title("batches in process")
    right.legend(fontsize=7, ncol=2)
    save(fig, path)
