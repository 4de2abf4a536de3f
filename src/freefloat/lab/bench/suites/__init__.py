"""The suites of ``freefloat bench --suite NAME``, one registry of objects: :data:`SUITES` (the
command's help and its check of the names read it).

A suite answers one question about speed (the loop's overhead, the GJM's cost against Pinocchio,
...) by measuring side by side in this process. ``mujoco`` (:class:`ScenesSuite`, the command's
default) is the race of work against precision with MuJoCo (:mod:`..race`); every other suite is
measured in parts (:class:`Suite`) and writes ``bench_<name>.json`` (its numbers, settings and
versions, rewritten after each part) and ``bench_<name>.png`` (its chart) into the bench's
folder (:mod:`.parts`).

A new suite is one module here with ``settings(quick, repeats) -> dict``, ``measure(settings)``
(yields ``(key, value)``, the report's parts, as each is measured) and ``chart(report, path)``,
plus one ``SUITES.register`` line. Modules are imported when their suite runs, so the command
line starts without them.
"""

from __future__ import annotations

import functools
import importlib
import importlib.util
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, ClassVar

from ....app.signals import signals_raise_keyboard_interrupt
from ....errors import InvalidArgument, MissingExtra, UnknownName, spelled
from ....registry import Registry
from ..options import Options

if TYPE_CHECKING:
    from ....app.run_folder import RunFolder
    from .parts import Ended

#: A prepared suite: measures into the held folder, calling ``progress`` with a line as it goes.
Measurement = Callable[["RunFolder", Callable[[str], None]], "Ended"]


@dataclass(frozen=True)
class Suite:
    """A suite measured in parts (see the package's docstring).

    Attributes:
        name: the ``--suite`` argument; its files are ``bench_<name>.json`` and ``.png``.
        help: one line for the command's help.
        module: its module in this package (``".gjm"``), or absolute.
        needs: ``(module, extra)`` of each optional package it imports, e.g. ``("mujoco",
            "bench")``: checked before anything runs, the error naming the extra to install.
    """

    name: str
    help: str
    module: str = ""
    needs: tuple[tuple[str, str], ...] = ()
    #: Whether the suite takes the command's scenes.
    takes_scenes: ClassVar[bool] = False

    def check_needs(self) -> None:
        """Raise ``MissingExtra`` naming the extra to install when a needed package is missing."""
        for module, extra in self.needs:
            if importlib.util.find_spec(module) is None:
                raise MissingExtra(f'the bench suite {self.name} needs {module}: python3 -m pip install -e ".[{extra}]"')

    def prepare(self, options: Options) -> Measurement:
        """Checked and imported before any folder is made; the measurement of :func:`.parts.run_parts`."""
        self.check_needs()
        from .parts import run_parts

        return functools.partial(run_parts, self.name, importlib.import_module(self.module, __name__), options)


@dataclass(frozen=True)
class ScenesSuite(Suite):
    """The race against MuJoCo over its scenes (:func:`..race.report.bench`: ``bench.json``,
    ``bench.csv``, ``<scene>.png``, ``summary.txt``); it has no :attr:`module`."""

    takes_scenes: ClassVar[bool] = True

    def prepare(self, options: Options) -> Measurement:
        """Checked, with its scenes built, before any folder is made (:func:`..race.report.prepared`)."""
        self.check_needs()
        from ..race.report import prepared
        from .parts import Ended

        measure = prepared(options)

        def run(folder: RunFolder, progress: Callable[[str], None]) -> Ended:
            report = measure(folder, progress)
            return Ended(report["status"], report["summary"])

        return run


#: Every suite, in the order the command lists and ``all`` runs them.
SUITES: Registry[Suite] = Registry("bench suite")
#: The suite ``freefloat bench`` runs when ``--suite`` is not given.
DEFAULT = "mujoco"
#: The ``--suite`` name of every suite.
ALL = "all"

for _suite in (
    ScenesSuite(DEFAULT, "freefloat's integrators against MuJoCo's, work against precision per scene (the default)",
                needs=(("mujoco", "bench"),)),
    Suite("simulation", "the loop's overhead against an inline Python loop and the C++ floor, planar against free "
                        "base, a detumble scene's loops", ".simulation"),
    Suite("integrators", "every integrator's work against precision, observed orders, cost per step and momentum "
                         "drift over a long run", ".integrators"),
    Suite("gjm", "the GJM quantities, compiled and numpy, against the Pinocchio floor, 8 to 192 joints, growth "
                 "exponents", ".gjm"),
    Suite("models", "every dynamics model's acceleration against pin.aba, 8 to 192 joints, growth exponents",
          ".models"),
    Suite("locking", 'joint locking and model = "auto" against the full exact plant', ".locking"),
    Suite("parallel", "the 5R's and the 2RSU+PPaP's dynamics against Pinocchio's constrained dynamics",
          ".parallel"),
    Suite("laws", "the 5R's platform laws like for like: cost per call, tracking and robustness on plants 15 % and "
                  "50 % off (computed torque, sliding mode, adaptive sliding mode, feedforward)", ".laws"),
    Suite("batch", "freefloat batch's runs per second serially, on 2 threads, on 2 processes and on Dask", ".batch",
          (("distributed", "dask"),)),
    Suite("figures", "writing a run's figures against the simulation itself", ".figures"),
    Suite("setup", "a run's fixed cost against its loop, nv 22 to 198, and a batch's runs per second, each run "
                   "fresh or reused", ".setup"),
    Suite("two_hands", "the two-hand capture's post-grasp phase (loop closure and its law) in the Python and the "
                       "compiled loop, against the single-arm capture's, per simulated second", ".two_hands"),
    Suite("atlas", "a 200 x 200 workspace and singularity map of the four arm robot's arm against as many "
                   "gjm.compute calls, serial and on 2 processes", ".atlas"),
    Suite("rollout", "a batch's runs per second on 1 and 2 threads against mujoco.rollout's, same robot and runs",
          ".rollout", (("mujoco", "bench"),)),
    Suite("kernel", "the dynamics kernel against Pinocchio's ABA and MuJoCo: per evaluation, per step, scalar and "
                    "lockstep, and batches against mujoco.rollout, nv 18 to 198", ".kernel", (("mujoco", "bench"),)),
):
    SUITES.register(_suite)


def named(names: list[str]) -> list[Suite]:
    """The suites called ``names``, each once, in the order given (``all``: every suite).

    Raises:
        UnknownName: a name not in :data:`SUITES` nor ``all``, listing the valid ones.
    """
    chosen: dict[str, Suite] = {}
    for name in names:
        if name not in SUITES and name != ALL:
            raise UnknownName("bench suite", name, [*SUITES, ALL])
        chosen.update(SUITES if name == ALL else {name: SUITES[name]})
    return list(chosen.values())


def run_suites(out: Path, names: list[str], options: Options, progress: Callable[[str], None] = print) -> list[Ended]:
    """Run the suites called ``names`` one after another into the folder ``out``.

    Every suite is checked and prepared first, so a bad name, a missing package or a bad scene
    stops the bench before the folder is made. Ctrl-C, SIGTERM or SIGHUP stops the suite that is
    running (it keeps what it measured) and the bench with it.

    Returns:
        How each suite that ran ended, the last one not ``"completed"`` if the bench stopped early.

    Raises:
        UnknownName: see :func:`named`.
        InvalidArgument: scenes given and no suite chosen takes them.
    """
    from ....app.run_folder import RunFolder

    suites = named(names)
    if options.scenes and not any(suite.takes_scenes for suite in suites):
        raise InvalidArgument(f"bench scenes ({', '.join(options.scenes)}) belong to the {DEFAULT} suite, which "
                              f"{spelled('suites=', '--suite')} leaves out")
    measurements = [suite.prepare(options) for suite in suites]
    ended: list[Ended] = []
    with RunFolder(out) as folder, signals_raise_keyboard_interrupt():
        for measure in measurements:
            ended.append(measure(folder, progress))
            if ended[-1].status != "completed":
                break
    return ended

from ....lazy import lazy_modules  # noqa: E402

__getattr__ = lazy_modules(__name__)  # its modules, imported on first use as attributes
