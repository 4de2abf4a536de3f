"""Command line: ``freefloat simulate [SCENE] [--out DIR]`` (robot and mechanism scenes),
``freefloat batch``, ``freefloat scenes``, ``freefloat robots``, ``freefloat verify``,
``freefloat atlas``, and the commands plug-ins register in :data:`~.commands.COMMANDS` (the lab's
``freefloat reproduce`` and ``freefloat bench``), loaded only when the command line may name one."""

from __future__ import annotations

import argparse
import importlib
import os
import sys
import time
import warnings
from importlib.metadata import version
from pathlib import Path
from typing import TYPE_CHECKING, Any, TextIO

from ..errors import FreefloatError, InvalidArgument, PluginError, SceneError, command_line, did_you_mean
from .atlas.kinds import KINDS as ATLAS_KINDS
from .commands import COMMANDS, Command
from .folder_names import default_folder
from .progress_bar import LoopBar
from .shown_warnings import HeldWarnings, shown_warnings
from .signals import arrived_before_main, cut_by_interrupt, signals_deferred, signals_raise_keyboard_interrupt

if TYPE_CHECKING:
    from .experiments import Outcome
    from .viz.live import LiveView

#: What ``freefloat --help`` says first (plain text: the terminal shows no markup).
DESCRIPTION = ("Dynamics, simulation and control of free-floating multi-arm space robots and of closed-chain "
               "mechanisms, on Pinocchio. Each command has its own --help.")
#: The module each command imports first (with the robot loaders and their libraries), while
#: Ctrl-C is deferred.
HEAVY = {"simulate": ".runner", "batch": ".batch", "verify": ".runner", "info": ".runner", "view": ".view",
         "atlas": ".atlas.engine"}
#: The commands freefloat itself has; any other is a plug-in's (:data:`~.commands.COMMANDS`).
BUILT_IN = ("simulate", "batch", "scenes", "robots", "info", "view", "verify", "atlas")


class _Parser(argparse.ArgumentParser):
    """argparse's parser, whose refusal of a choice (a command, a study, a base) names the nearest
    valid ones as every other unknown name does (:func:`~freefloat.errors.did_you_mean`)."""

    def _check_value(self, action: argparse.Action, value: Any) -> None:  # argparse's hook for choices
        if action.choices is not None and value not in action.choices:
            raise argparse.ArgumentError(action, f"invalid choice: {value!r}{did_you_mean(value, action.choices)}")


def main(argv: list[str] | None = None) -> int:
    """Entry point; returns the exit status (0 ok, 1 run stopped early, 2 bad input)."""
    argv = sys.argv[1:] if argv is None else list(argv)
    try:
        plugged = _plugged(argv)
    except FreefloatError as exc:  # a plug-in that fails to import
        print(f"freefloat: error: {exc}", file=sys.stderr)
        return 2
    parser = _Parser(prog="freefloat", description=DESCRIPTION)
    parser.add_argument("--version", action="version", version=f"freefloat {version('freefloat')}")
    commands = parser.add_subparsers(dest="command", required=True)
    sim = commands.add_parser("simulate", help="run a scene and write its output folder")
    sim.add_argument("scene", nargs="?", default=None, help="built-in scene name or TOML file (default: the dissertation's ch. 4 task)")
    sim.add_argument("--robot", default=None,
                     help="run this robot instead (URDF file or a known name such as ur5 or solo12); without "
                          "a scene: the torque-free 'tumbling' scene")
    sim.add_argument("--out", type=Path, default=None, help="output folder (default: runs/<scene>-<time>)")
    sim.add_argument("--no-figures", action="store_true", help="skip the figures")
    sim.add_argument("--figures", default=None, metavar="NAME,...",
                     help="the figures to draw, comma-separated ('all': every one; '': none); default: the scene's "
                          "[output] figures, a lean set (docs/commands.md lists the names)")
    sim.add_argument("--no-html", action="store_true", help="skip the meshcat animation")
    sim.add_argument("--quiet", action="store_true", help="no progress bar")
    sim.add_argument("--overwrite", action="store_true",
                     help="replace the previous run in --out (default: refuse a folder that is not empty)")
    sim.add_argument("--view", action="store_true",
                     help="show the run live in a meshcat viewer as it is computed, then replay it (robot runs); "
                          "other runs open their page when it is written")
    bat = commands.add_parser("batch", help="N seeded runs of a scene with its start or plant varied, into one table")
    bat.add_argument("scene", nargs="?", default=None, help="built-in scene name or TOML file (default: the ch. 4 task)")
    bat.add_argument("--runs", type=int, default=10, help="number of runs (default 10)")
    bat.add_argument("--seed", type=int, default=0,
                     help="seed of the batch: the first run's seed; each run's own seed is in its row of runs.csv, "
                          "and given here reruns that row (default 0)")
    bat.add_argument("--vary", action="append", default=[], metavar="KEY=WIDTH",
                     help="vary KEY uniformly within +-WIDTH about the scene's value (repeatable): "
                          + "; ".join(f"{k}: {d}" for k, d in _varies().items()).replace("%", "%%"))
    bat.add_argument("--workers", type=int, default=None,
                     help="worker processes (default 1: one run after another in this process)")
    bat.add_argument("--force-workers", action="store_true",
                     help="start --workers processes even beyond the cores (capped at the cores, at least 4, without)")
    bat.add_argument("--dask", action="store_true", help="run on Dask: a local cluster of --workers (default 2) "
                                                         "processes, or --scheduler's workers")
    bat.add_argument("--scheduler", default=None, help="with --dask: a Dask scheduler's address (tcp://host:8786)")
    bat.add_argument("--threads", type=int, default=1,
                     help="runs at once on threads of this process (default 1); with --dask, threads of each "
                          "local worker")
    bat.add_argument("--out", type=Path, default=None, help="output folder (default: runs/batch-<scene>-<time>)")
    bat.add_argument("--overwrite", action="store_true", help="replace the previous batch in --out")
    bat.add_argument("--quiet", action="store_true", help="no progress bar")
    commands.add_parser("scenes", help="list the built-in scenes")
    commands.add_parser("robots", help="list the robots known by name (freefloat's own and example-robot-data's)")
    info = commands.add_parser("info", help="joints, links, masses, end-effectors and warnings of a robot")
    info.add_argument("robot", help="URDF file, or the name of a known robot (ur5, solo12, panda, ...)")
    info.add_argument("--base", choices=["free", "planar"], default="free", help="floating base (default free)")
    view = commands.add_parser("view", help="reopen a saved run's meshcat page (rebuilt if the run has none)")
    view.add_argument("run_dir", type=Path, help="a run folder written by freefloat simulate")
    view.add_argument("--no-browser", action="store_true", help="only print the page's path")
    ver = commands.add_parser("verify", help="cross-check the hand-built GJM matrices against Pinocchio")
    ver.add_argument("urdf", type=Path, help="URDF file (loaded with a free-flyer base)")
    ver.add_argument("--samples", type=int, default=10, help="random states to check (default 10)")
    ver.add_argument("--seed", type=int, default=0, help="random seed (default 0)")
    ver.add_argument("--json", type=Path, default=None, help="also write the report as JSON here")
    for command in plugged:
        command.arguments(commands.add_parser(command.name, help=command.help))
    _atlas_parser(commands, listed="atlas" in argv)
    args = parser.parse_args(argv)
    commands_run = {"simulate": _simulate, "batch": _batch, "scenes": lambda _: _scenes(),
                    "robots": lambda _: _robots(), "verify": _verify, "info": _info, "view": _view, "atlas": _atlas,
                    **{command.name: command.run for command in plugged}}
    heavy = {**HEAVY, **{command.name: command.heavy for command in plugged if command.heavy}}
    try:
        early_too = arrived_before_main()
        with signals_deferred() as early:  # Ctrl-C while importing: trimesh would swallow it
            if args.command == "simulate" and _may_draw_figures(args):
                from .viz import rendering

                rendering.warm_up()  # its imports (~0.7 s of CPU) overlap this process's
            if args.command in heavy:
                importlib.import_module(heavy[args.command], __package__)
        if early.is_set() or early_too:
            raise KeyboardInterrupt("while starting; nothing was written")
        with signals_raise_keyboard_interrupt(), command_line():  # SIGTERM, SIGHUP: Ctrl-C; messages name options
            try:
                return commands_run[args.command](args)
            except ImportError as exc:  # an interrupt inside a compiled module's import: still an interrupt
                stop = cut_by_interrupt(exc)
                if stop is None:
                    raise  # a real ImportError keeps its traceback and context
                raise stop from None
    except FreefloatError as exc:
        print(f"freefloat: error: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt as exc:
        detail = str(exc) if str(exc) and not str(exc).startswith("SIG") else ""
        print(f"freefloat: interrupted{'' if detail.startswith(';') or not detail else ' '}{detail}", file=sys.stderr)
        return 1


def _plugged(argv: list[str]) -> list[Command]:
    """The plug-ins' commands, when ``argv`` may name one or asks for the list (``--help``, no
    command, a command freefloat does not have): not for a built-in command or ``--version``,
    which start without reading the installed packages' entry points.

    Raises:
        PluginError: a plug-in failed to import, or named its command like a built-in one.
    """
    first = next((k for k, arg in enumerate(argv) if not arg.startswith("-")), len(argv))
    if "--version" in argv[:first] or (first < len(argv) and argv[first] in BUILT_IN):
        return []
    taken = [name for name in COMMANDS if name in BUILT_IN]
    if taken:
        raise PluginError(f"a plug-in registers the command '{taken[0]}', which is freefloat's own")
    return [COMMANDS[name] for name in COMMANDS]


def _atlas_parser(commands: Any, listed: bool) -> None:
    """The ``atlas`` subcommand's arguments; with ``listed`` (the command line names it), the kinds'
    names and help from their registry (a lookup loads the plug-ins, which may add kinds)."""
    atl = commands.add_parser("atlas", help="a map over a grid: free-floating workspace, dynamic singularities, ... "
                                            "(data, summary and figures into one folder)")
    atl.add_argument("kind", metavar="KIND", help="; ".join(f"{k.name}: {k.help} (TARGET: {k.target})"
                                                          for k in ATLAS_KINDS.values()) if listed else "the map")
    atl.add_argument("target", metavar="TARGET", help="what the kind maps: a robot's name or URDF file, a mechanism")
    atl.add_argument("--grid", type=int, default=None, help="points per grid axis (default: the kind's)")
    atl.add_argument("--axes", default=None, metavar="A,B,...",
                     help="the grid's axes, comma-separated (joints of the mapped arm; default: the kind's)")
    atl.add_argument("--end-effector", default=None, help="the end-effector mapped (default: the robot's first)")
    atl.add_argument("--momentum", type=float, nargs="+", default=None, metavar="M",
                     help="the system momentum [P; L] about the system CoM, inertial frame (6 numbers, or 3 for a "
                          "planar base: Px Py Lz; default zero)")
    atl.add_argument("--tolerance", type=float, default=None,
                     help="sigma_min / sigma_max below which a Jacobian counts as singular (default: the kind's)")
    atl.add_argument("--base", choices=["free", "planar"], default=None,
                     help="floating base of a robot given by name or file (default: planar for freefloat's planar "
                          "robots, free otherwise)")
    atl.add_argument("--posture", default=None, metavar="JOINT=VALUE,...",
                     help="positions of the held joints, deg (revolute) or m (prismatic), comma-separated "
                          "(default: the four-arm robot's Table 4 start, mid-range for other robots)")
    atl.add_argument("--workers", type=int, default=None,
                     help="processes evaluating the map, this one included (default 1: this process alone)")
    atl.add_argument("--force-workers", action="store_true",
                     help="start --workers processes even beyond the cores (capped at the cores, at least 4, without)")
    atl.add_argument("--dask", action="store_true", help="evaluate on Dask: a local cluster of --workers (default 2) "
                                                         "processes, or --scheduler's workers")
    atl.add_argument("--scheduler", default=None, help="with --dask: a Dask scheduler's address (tcp://host:8786)")
    atl.add_argument("--out", type=Path, default=None,
                     help="output folder (default: runs/atlas-<kind>-<target>-<time>)")
    atl.add_argument("--overwrite", action="store_true",
                     help="replace the atlas freefloat wrote in --out (default: resume it from its journal)")
    atl.add_argument("--quiet", action="store_true", help="no progress bar")


def _atlas(args: argparse.Namespace) -> int:
    from ..extras import require
    from .atlas.engine import run_atlas
    from .atlas.kinds import Options
    from .batch import Workers
    from .summary_text import shown

    ATLAS_KINDS.get(args.kind)
    if args.dask or args.scheduler is not None:
        require("dask", "freefloat atlas --dask")
    if args.scheduler is not None and args.workers is not None:
        raise InvalidArgument("--workers sets the size of a local cluster; with --scheduler the scheduler's workers run")
    workers = Workers((2 if args.dask else 1) if args.workers is None else args.workers,
                      args.dask or args.scheduler is not None, args.scheduler, force=args.force_workers)
    options = Options(grid=args.grid, axes=tuple(args.axes.split(",")) if args.axes else None,
                      end_effector=args.end_effector, momentum=tuple(args.momentum) if args.momentum else None,
                      tolerance=args.tolerance, base=args.base, posture=_pairs(args.posture))
    out = args.out or default_folder(f"atlas-{args.kind}-{Path(args.target).stem}")
    with shown_warnings() as held:
        bar = LoopBar(None, args.kind, "pt", args.quiet, started=held.release)  # closed once every point is in
        try:
            done = run_atlas(args.kind, args.target, options, out, workers, args.overwrite, bar)
        finally:
            bar.close()
    resumed = done.grid.size - done.summary["points_mapped"]
    print(f"{args.kind} of {args.target}: {done.summary['points_mapped']} points in "  # the time the bar showed
          f"{done.summary['map_wall_time_s']:.2f} s ({workers.label}){f', {resumed} resumed' if resumed else ''} "
          f"-> {done.folder}")
    units = getattr(ATLAS_KINDS.get(args.kind).load(), "SUMMARY_UNITS", {})
    for key, value in done.summary["summary"].items():
        if not isinstance(value, (dict, list)):
            print(f"  {key}: {shown(value, units.get(key, ''))}")
    print(f"  wrote: {', '.join(p.name for p in done.written)}")
    return 0


def _pairs(text: str | None) -> tuple[tuple[str, float], ...] | None:
    """``JOINT=VALUE,...`` as ``((joint, value), ...)``.

    Raises:
        FreefloatError: naming the item that is not NAME=NUMBER.
    """
    if not text:
        return None
    pairs = []
    for item in text.split(","):
        name, _, value = item.partition("=")
        try:
            pairs.append((name.strip(), float(value)))
        except ValueError:
            raise InvalidArgument(f"--posture: '{item}' is not JOINT=VALUE (e.g. elbow_joint=30)") from None
    return tuple(pairs)


def _varies() -> dict[str, str]:
    from .batch.bands import VARIES

    return VARIES


def _batch(args: argparse.Namespace) -> int:
    from ..extras import require
    from .batch import Workers, parse_band, run_batch
    from .experiments import summary_units
    from .scenes import DEFAULT_SCENE, find_scene
    from .summary_text import shown

    if args.dask or args.scheduler is not None:
        require("dask", "freefloat batch --dask" if args.dask else "freefloat batch --scheduler")
    if args.scheduler is not None and args.workers is not None:
        raise InvalidArgument("--workers sets the size of a local cluster; with --scheduler the scheduler's workers run")
    default = 2 if args.dask or args.scheduler else 1
    workers = Workers(default if args.workers is None else args.workers, args.dask or args.scheduler is not None,
                      args.scheduler, args.threads, args.force_workers)
    bands = [parse_band(text) for text in args.vary]
    scene = find_scene(args.scene or DEFAULT_SCENE)
    out = args.out or default_folder(f"batch-{scene.name}")
    with shown_warnings() as held:
        if not bands and args.runs > 1:
            warnings.warn(f"no --vary: the {args.runs} runs start alike and give the same numbers (vary them with "
                          "--vary KEY=WIDTH, see freefloat batch --help)", stacklevel=1)
        bar, finished = LoopBar(args.runs, scene.name, "run", args.quiet, started=held.release), [0]

        def progress(row: dict) -> None:
            finished[0] += 1
            bar(finished[0])

        try:
            done = run_batch(scene, out, args.runs, bands, args.seed, workers, args.overwrite, progress,
                             started=lambda: bar(0))
        finally:
            bar.close()
    summary = done.summary
    counts = ", ".join(f"{n} {status}" for status, n in sorted(summary["by_status"].items()))
    print(f"{summary['status']}: {summary['by_status'].get('completed', 0)} of {summary['runs']} runs completed "
          f"({counts or 'none run'}) in "
          f"{summary['wall_time_s']:.2f} s, {summary['runs_per_second'] or 0:.2f} runs/s ({workers.label}) -> {out}")
    units = summary_units(scene)
    for key, spread in summary["spread"].items():
        print(f"  {key}: min {shown(spread['min'])}, median {shown(spread['median'])}, max "
              f"{shown(spread['max'], units.get(key.split('[')[0], ''))}")
    if not done.completed:
        print(f"freefloat: batch not all completed: {summary['not_run']} not run, "
              f"{summary['finished'] - summary['by_status'].get('completed', 0)} stopped early or failed "
              f"(rows in {out / 'runs.csv'})", file=sys.stderr)
        return 1
    return 0


def _view(args: argparse.Namespace) -> int:
    import webbrowser

    from .view import run_page

    page = run_page(args.run_dir)
    print(page)
    if not args.no_browser:
        webbrowser.open(page.resolve().as_uri())
    return 0


def _scenes() -> int:
    from ..inputs import read_toml
    from .scenes import DEFAULT_SCENE, builtin_scenes

    for name, path in builtin_scenes().items():  # their descriptions only: no registry (no plug-in) is read
        mark = " (default)" if name == DEFAULT_SCENE else ""
        print(f"{name}{mark}: {read_toml(path, 'scene file', SceneError).get('description', '')}")
    return 0


def _robots() -> int:
    from ..robot.catalog import robots

    for name, path in robots().items():
        print(f"{name}: {path.name}" if name != path.stem else name)
    return 0


def _info(args: argparse.Namespace) -> int:
    from ..robot.describe import describe
    from ..robot.loading import load_robot

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # describe() lists them
        robot = load_robot(args.robot, base=args.base, visuals=False)
    print(describe(robot))
    return 0


def _verify(args: argparse.Namespace) -> int:
    from ..dynamics.verify import MAX_SAMPLES, check_robot, write_report
    from ..robot.loading import load_robot

    if not 1 <= args.samples <= MAX_SAMPLES:
        raise InvalidArgument(f"--samples must be from 1 to {MAX_SAMPLES}, got {args.samples}")
    if args.seed < 0:
        raise InvalidArgument(f"--seed must be >= 0, got {args.seed}")
    if args.json is not None and (args.json.is_dir() or not args.json.parent.is_dir()):
        raise InvalidArgument(f"--json {args.json}: must be a file in an existing folder")
    with shown_warnings():
        robot = load_robot(args.urdf, visuals=False)
    report = check_robot(robot, samples=args.samples, seed=args.seed)
    print(report.table())
    if args.json is not None:
        try:
            write_report(report, args.json)
        except OSError as exc:
            raise InvalidArgument(f"--json {args.json}: cannot write ({exc.strerror or exc})") from exc
    return 0 if report.passed else 1


def _may_draw_figures(args: argparse.Namespace) -> bool:
    """Whether ``simulate`` may draw figures, told before the imports that parse its scene: not
    when the options or the scene file's ``[output] figures`` (read here as bare TOML) turn them
    off. A guess on the safe side: the scene is parsed and checked later, and a figure helper
    started for a scene that draws none is ended then (:func:`~.viz.rendering.cool_down`)."""
    import tomllib

    from ..paths import SCENES_DIR

    if args.no_figures or args.figures is not None:
        return not args.no_figures and bool(args.figures.strip(", "))
    if args.scene is None:
        return True  # the built-in default scenes draw figures
    builtin = SCENES_DIR / f"{args.scene}.toml"
    try:
        output = tomllib.loads((builtin if builtin.is_file() else Path(args.scene)).read_text()).get("output")
    except (OSError, ValueError):  # the scene's own parse names the problem
        return False
    return not isinstance(output, dict) or output.get("figures", True) not in (False, [])


def _simulate(args: argparse.Namespace) -> int:
    import dataclasses

    from .experiments import summary_units
    from .scenes import DEFAULT_SCENE, ROBOT_SCENE, find_scene, with_robot

    scene = find_scene(args.scene or (ROBOT_SCENE if args.robot else DEFAULT_SCENE))
    if args.robot is not None:
        scene = with_robot(scene, args.robot)
    if args.figures is not None:
        from . import figure_set

        chosen = figure_set.parse_names(args.figures, "--figures", SceneError)
        scene = dataclasses.replace(scene, output=dataclasses.replace(scene.output, figures=chosen))
    if args.no_figures or args.no_html:
        output = dataclasses.replace(scene.output, figures=scene.output.figures and not args.no_figures,
                                     html=scene.output.html and not args.no_html)
        scene = dataclasses.replace(scene, output=output)
    if scene.output.figures:
        from .viz import rendering

        rendering.warm_up()  # started by main() already, before the imports
    elif _may_draw_figures(args):  # main() started the helper on a guess the scene overrules
        from .viz import rendering

        rendering.cool_down()  # its imports would only slow the run
    from .runner import prepare, simulate, total_steps

    out = args.out or default_folder(scene.name)
    with shown_warnings() as held:
        with signals_deferred() as early:
            setup = prepare(scene)
        if early.is_set():
            raise KeyboardInterrupt("before the run started; nothing was written")
        live = _live_view(scene, setup) if args.view else None
        stages = _Stages(args.quiet, held)
        stages.bar = LoopBar(total_steps(scene), scene.name, "step", args.quiet, started=held.release,
                             ended=lambda: stages.begin("summarising the run"))
        try:
            units = summary_units(scene)
            done = simulate(scene, out=out, overwrite=args.overwrite, progress=stages.bar, setup=setup,
                            checkpoint=live.show if live else None, stage=stages,
                            summarised=lambda outcome: (stages.finish(), _summary(outcome, units, out)))
            stages.finish()
            status = _report(done)
            if live is not None:
                tel = done.telemetry
                print("replaying the run in the live viewer")
                live.replay(tel.t, tel.q)
                if sys.stdin.isatty():
                    input("press Enter to close the viewer ")
            elif args.view and (out / "trajectory.html").is_file():
                import webbrowser

                webbrowser.open((out / "trajectory.html").resolve().as_uri())
        finally:
            stages.bar.close()
            if live is not None:
                live.close()
    return status


class _Stages:
    """What ``freefloat simulate`` shows after the loop: its progress bar (:attr:`bar`, whose time
    is the loop's) closed as the loop ends, then a line per stage with the time it took: the
    summary, then each writing stage (:data:`~.outputs.STAGES`)."""

    def __init__(self, quiet: bool, held: HeldWarnings) -> None:
        self.quiet, self.held = quiet, held
        self.bar: LoopBar | None = None
        self.started: float | None = None

    def __call__(self, name: str) -> None:
        from .outputs import STAGES

        self.begin(f"writing {STAGES[name]}")

    def begin(self, label: str) -> None:
        """End the bar and the stage under way, and start the stage ``label``."""
        if self.bar is not None:
            self.bar.close()
        self.held.release()  # a run that never reported (a capture) is past its checks too
        self.finish()
        self.started = time.perf_counter()
        if not self.quiet:
            _said(f"{label} ...", sys.stderr, end="")

    def finish(self) -> None:
        """End the stage under way (its time on its line)."""
        if self.started is not None and not self.quiet:
            _said(f" {time.perf_counter() - self.started:.2f} s", sys.stderr)
        self.started = None


def _live_view(scene, setup) -> LiveView | None:
    """A live viewer of the scene's robot (joint-space and detumbling runs; a capture changes the
    robot mid-run and a mechanism is no tree, so those open their page after the run)."""
    if scene.kind not in ("joint_space", "detumbling"):
        print(f"freefloat: the live viewer shows joint-space and detumbling runs; this {scene.kind} run's page "
              "opens when it is written", file=sys.stderr)
        return None
    import webbrowser

    from .viz.live import LiveView

    live = LiveView(setup.robot)
    print(f"live viewer: {live.url}")
    webbrowser.open(live.url)
    return live


def _summary(outcome: Outcome, units: dict[str, str], out: Path) -> None:
    """Print a run's outcome and its headline summary keys (:func:`~.summary_text.shown`, in
    ``units``), as soon as they are final: before the run folder ``out`` is written."""
    from .summary_text import shown

    _said(f"{outcome.status}: {outcome.steps} steps in {outcome.wall_time_s:.2f} s -> {out}")
    for key in outcome.headline:
        if key in outcome.summary:
            _said(f"  {key}: {shown(outcome.summary[key], units.get(key, ''))}")


def _said(text: str, stream: TextIO | None = None, end: str = "\n") -> None:
    """Print ``text`` on ``stream`` (default standard output), flushed. Once its reader is gone
    (``| head`` closed the pipe), this and every later line go to the null device: the run goes
    on writing its files."""
    stream = stream or sys.stdout
    try:
        print(text, end=end, file=stream, flush=True)
    except BrokenPipeError:
        null = os.open(os.devnull, os.O_WRONLY)
        os.dup2(null, stream.fileno())
        os.close(null)


def _report(outcome: Outcome) -> int:
    """Print what a written run wrote and skipped (its summary is printed already: :func:`_summary`);
    the exit status (1 when it stopped early, or an interrupt came while it was written)."""
    out = outcome.folder
    _said(f"  wrote: {', '.join(p.name for p in outcome.written)}")
    if outcome.skipped:
        _said(f"  skipped: {', '.join(outcome.skipped)}")
    if not outcome.completed:
        what, kept = ("failed", "results") if outcome.status == "failed" else ("stopped early", "partial results")
        print(f"freefloat: run {what}: {outcome.message} ({kept} kept in {out})", file=sys.stderr)
        return 1
    if outcome.interrupted_writing:  # exit 1 even when the interrupt came too late to cut anything short
        left = "the drawings listed as skipped are not there" if outcome.skipped else "every file listed was written"
        print(f"freefloat: interrupted while writing {out}: the data are whole, {left}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
