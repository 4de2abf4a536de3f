"""A corpus of mutated URDFs, scenes and closure files, generated from seeds, and the harness that
runs each through ``freefloat simulate``: every case must end in success, a run stopped early
(exit 1, with its partial results) or a clean refusal (exit 2, ``freefloat: error: ...``) within a
time bound, never a traceback, a hang, a crash, a non-finite result or a file outside its folder.
The other classes of the corpus (``fuzzing_*.py``; ``fuzz_corpus.py`` lists them all) share
:func:`cli` and :func:`verdict`.

``tests/test_fuzz.py`` runs a short slice; ``scripts/fuzz.py`` runs the whole corpus and counts.
"""

from __future__ import annotations

import contextlib
import io
import json
import random
import signal
import tomllib
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from pathlib import Path

from freefloat.app.cli import main
from freefloat.app.conservation_check import check
from freefloat.app.scenes import builtin_scenes
from freefloat.paths import URDF_DIR

from .conftest import toml_text

#: Seconds one case may take.
TIME_BOUND = 60.0
BAD_NUMBERS = ["nan", "inf", "-inf", "0", "-1", "1e308", "1e-308", "-1e308", "abc", "", "1 2", "0x10"]
HOSTILE_MESHES = ["file:///etc/passwd", "package://../../../../etc/passwd", "../../../../etc/hostname",
                  "/dev/zero", "missing.dae"]
SEED_URDFS = ["two_arm_planar.urdf", "four_arm_planar.urdf", "five_bar.urdf"]
SEED_SCENES = ["four_arm_joint_space", "detumble_impulse_arm1_joint4", "tumbling", "five_bar_computed_torque",
               "capture_planar"]


@dataclass
class Case:
    """One generated input: the files to write into a fresh folder, and the scene to run."""

    kind: str  # "urdf" or "scene"
    seed: int
    files: dict[str, str | bytes]
    scene: str
    mutation: str

    def run(self, folder: Path) -> tuple[str, str]:
        """Run the case in ``folder``: its outcome and detail (see :func:`run_case`)."""
        return run_case(self, folder)


def _urdf_mutation(rng: random.Random, text: str) -> tuple[str | bytes, str]:
    """One random corruption of URDF text, and what it was."""
    root = ET.fromstring(text)
    elements = list(root.iter())
    choice = rng.randrange(12)
    if choice == 0:
        victim = rng.choice(elements[1:])
        for parent in root.iter():
            if victim in list(parent):
                parent.remove(victim)
                return ET.tostring(root, encoding="unicode"), f"dropped <{victim.tag}>"
    if choice in (1, 2, 3):
        element = rng.choice([e for e in elements if e.attrib])
        attribute = rng.choice(sorted(element.attrib))
        value = rng.choice(BAD_NUMBERS) if choice != 3 else " ".join(rng.choice(BAD_NUMBERS) for _ in range(3))
        element.set(attribute, value)
        return ET.tostring(root, encoding="unicode"), f"<{element.tag} {attribute}='{value}'>"
    if choice == 4:
        element = rng.choice([e for e in elements if e.attrib])
        attribute = rng.choice(sorted(element.attrib))
        del element.attrib[attribute]
        return ET.tostring(root, encoding="unicode"), f"removed {element.tag}@{attribute}"
    if choice == 5:
        victim = rng.choice(root.findall("link") + root.findall("joint"))
        root.append(ET.fromstring(ET.tostring(victim)))
        return ET.tostring(root, encoding="unicode"), f"duplicated {victim.tag} {victim.get('name')}"
    if choice == 6:
        joints, links = root.findall("joint"), [link.get("name") for link in root.findall("link")]
        joint = rng.choice(joints)
        target = rng.choice(["parent", "child"])
        joint.find(target).set("link", rng.choice(links + ["nowhere"]))
        return ET.tostring(root, encoding="unicode"), f"rewired {joint.get('name')} {target}"
    if choice == 7:
        joint = rng.choice(root.findall("joint"))
        kind = rng.choice(["floating", "planar", "spherical", "xyz", "continuous", "prismatic", "fixed", ""])
        joint.set("type", kind)
        return ET.tostring(root, encoding="unicode"), f"joint {joint.get('name')} type '{kind}'"
    if choice == 8:
        mass = rng.choice(root.findall(".//mass"))
        value = rng.choice(["1e30", "1e-30", "0", "1e-300", "-5"])
        mass.set("value", value)
        return ET.tostring(root, encoding="unicode"), f"mass {value}"
    if choice == 9:
        link = rng.choice(root.findall("link"))
        mesh = rng.choice(HOSTILE_MESHES)
        link.append(ET.fromstring(f'<visual><geometry><mesh filename="{mesh}"/></geometry></visual>'))
        return ET.tostring(root, encoding="unicode"), f"mesh {mesh}"
    if choice == 10:
        cut = rng.randrange(len(text))
        return text[:cut], f"truncated at {cut}"
    hostile = rng.choice([
        '<!DOCTYPE r [<!ENTITY x SYSTEM "file:///etc/passwd">]>',
        '<!DOCTYPE r [<!ENTITY a "aaaaaaaaaaaaaaaa"><!ENTITY b "&a;&a;&a;&a;&a;&a;&a;&a;">]>',
    ])
    return hostile + text.replace('name="', 'name="&x;' if "SYSTEM" in hostile else 'name="&b;', 1), "entities"


def _value_mutation(rng: random.Random, raw: dict) -> str:
    """Corrupt one value (or key) of a parsed TOML table in place; what it was."""
    tables = [(None, raw)] + [(k, v) for k, v in raw.items() if isinstance(v, dict)]
    name, table = rng.choice(tables)
    keys = sorted(table)
    choice = rng.randrange(5)
    if choice == 0 or not keys:
        table[rng.choice(["speed", "colour", "x"])] = 1
        return f"unknown key in [{name}]"
    key = rng.choice(keys)
    if choice == 1:
        del table[key]
        return f"deleted {name}.{key}"
    if choice == 2:
        table[key] = rng.choice(["", "../../../etc/passwd", "/tmp", "nosuch", "é" * 3, "a" * 500])
        return f"{name}.{key} = a string"
    if choice == 3:
        table[key] = rng.choice([0, -1, 1e308, -1e-9, 10**12, 3.5, True, [], [1.0] * 7, {"a": 1}])
        return f"{name}.{key} = {table[key]!r}"[:80]
    table[key] = rng.choice([float("nan"), float("inf")]) if rng.random() < 0.5 else [float("nan")] * 3
    return f"{name}.{key} = non-finite"


def urdf_case(seed: int) -> Case:
    """A tumbling scene on a mutated copy of one of the built-in URDFs."""
    rng = random.Random(seed)
    source = rng.choice(SEED_URDFS)
    text, mutation = _urdf_mutation(rng, (URDF_DIR / source).read_text())
    scene = {"name": f"fuzz{seed}", "robot": {"urdf": "robot.urdf", "base": rng.choice(["free", "planar"])},
             "task": {"kind": "none"}, "controller": {"kind": "none"},
             "initial": {"base_angular_velocity": [5.0, -3.0, 8.0]},
             "simulation": {"duration": 0.01, "control_period": 0.001},
             "output": {"figures": False, "html": rng.random() < 0.3}}
    return Case("urdf", seed, {"robot.urdf": text, "scene.toml": toml_text(scene)}, "scene.toml",
                f"{source}: {mutation}")


def scene_case(seed: int) -> Case:
    """A mutated copy of a built-in scene (shortened), or of its mechanism's closure file."""
    rng = random.Random(seed)
    source = rng.choice(SEED_SCENES)
    raw = tomllib.loads(builtin_scenes()[source].read_text())
    raw.setdefault("output", {}).update(figures=False, html=False)
    sim = raw["simulation"]
    period = sim.get("control_period", sim.get("step", 1e-3))
    sim["duration"] = 10 * period
    if "task" in raw and raw["task"].get("kind") == "joint_quintic":
        raw["task"]["duration"] = sim["duration"]
    if "target" in raw:
        raw["target"]["contact_time"] = 5 * period
    files: dict[str, str | bytes] = {}
    if "mechanism" in raw and rng.random() < 0.5:
        closure = tomllib.loads((URDF_DIR / raw["mechanism"]["closure"]).read_text())
        mutation = "closure: " + _value_mutation(rng, closure)
        closure["urdf"] = str(URDF_DIR / closure["urdf"]) if isinstance(closure.get("urdf"), str) and \
            (URDF_DIR / closure["urdf"]).is_file() else closure.get("urdf", "")
        files["closure.toml"] = toml_text(closure)
        raw["mechanism"]["closure"] = "closure.toml"
    elif rng.random() < 0.1:
        files["scene.toml"] = toml_text(raw).encode("utf-8")[: rng.randrange(10, 200)] + b"\xff\xfe"
        return Case("scene", seed, files, "scene.toml", f"{source}: bad bytes")
    else:
        mutation = _value_mutation(rng, raw)
    files["scene.toml"] = toml_text(raw)
    return Case("scene", seed, files, "scene.toml", f"{source}: {mutation}")


class Failure(Exception):
    """A case that ended in a failure: its outcome (``traceback``, ``hang``, ...) and detail."""

    def __init__(self, outcome: str, detail: str):
        super().__init__(f"{outcome}: {detail}")
        self.outcome, self.detail = outcome, detail


class _Timeout(Exception):
    pass


def cli(argv: list[str], cwd: Path | None = None) -> tuple[int, str]:
    """``freefloat ARGV`` in this process (in ``cwd`` if given) within :data:`TIME_BOUND`: its
    exit status and standard error.

    Raises:
        Failure: ``hang`` past the bound, ``traceback`` when anything escapes ``main``.
    """
    import os

    err = io.StringIO()

    def expire(signum, frame):
        raise _Timeout()

    previous = signal.signal(signal.SIGALRM, expire)
    signal.setitimer(signal.ITIMER_REAL, TIME_BOUND)
    before = os.getcwd()
    try:
        if cwd is not None:
            os.chdir(cwd)
        with contextlib.redirect_stderr(err), contextlib.redirect_stdout(io.StringIO()):
            status = main(argv)
    except _Timeout:
        raise Failure("hang", f"over {TIME_BOUND:g} s") from None
    except BaseException as exc:  # noqa: BLE001 - the point is to catch anything that escapes
        raise Failure("traceback", f"{type(exc).__name__}: {exc}"[:300]) from None
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, previous)
        os.chdir(before)
    return status, err.getvalue()


def verdict(status: int, err: str) -> tuple[str, str]:
    """The outcome of an exit status: ``completed`` (0), ``stopped`` (1), ``refused`` (2 with
    one ``freefloat: error:`` line), else ``traceback``; and its detail."""
    last = err.strip().splitlines()[-1] if err.strip() else ""
    if status == 0:
        return "completed", ""
    if status == 1:
        return "stopped", last
    if status == 2 and last.startswith("freefloat: error: "):
        return "refused", last
    return "traceback", f"exit {status}: {last}"


def run_case(case: Case, folder: Path) -> tuple[str, str]:
    """Run ``case`` in ``folder`` (its working directory): the outcome (``completed``,
    ``stopped``, ``refused``, or a failure: ``traceback``, ``hang``, ``non-finite``,
    ``escaped``, ``violated``: a conservation law broken in a run reported completed) and a detail."""
    import os

    folder.mkdir(parents=True, exist_ok=True)
    for name, content in case.files.items():
        (folder / name).write_bytes(content if isinstance(content, bytes) else content.encode("utf-8"))
    before = set(os.listdir(folder))
    try:
        status, err = cli(["simulate", case.scene, "--quiet"], folder)
    except Failure as failure:
        return failure.outcome, failure.detail
    new = set(os.listdir(folder)) - before
    if new - {"runs"}:
        return "escaped", f"wrote {sorted(new - {'runs'})} beside the run folder"
    if status == 2:
        return verdict(status, err)
    runs = list((folder / "runs").iterdir()) if (folder / "runs").is_dir() else []
    if len(runs) != 1:
        return "escaped", f"{len(runs)} run folders under runs/"
    try:
        summary = json.loads((runs[0] / "summary.json").read_text(),
                             parse_constant=lambda c: (_ for _ in ()).throw(ValueError(c)))
    except (OSError, ValueError) as exc:
        return "non-finite", f"summary.json: {exc}"
    if status == 0 and summary.get("status") == "completed":
        violation = check(summary)  # the runner's own oracle: a broken conservation law is no success
        return ("violated", violation) if violation else ("completed", "")
    if status == 1 and summary.get("status") != "completed":
        return "stopped", summary.get("message", "")
    return "traceback", f"exit {status} with status {summary.get('status')}"


#: Outcomes that are no failure: a run that completed, one stopped early with its partial
#: results, a clean refusal. Anything else is a failure: ``traceback``, ``hang``, ``crash``,
#: ``non-finite``, ``escaped`` (a file outside the run folder), ``touched`` (a user's file
#: changed), ``followed`` (a link's target changed), ``network`` (a page names a URL's host),
#: ``corrupted`` (a file cut short, a telemetry row lost or repeated), ``not-resumable``,
#: ``accepted`` (a plainly wrong argument taken), ``violated`` (a completed run that breaks a
#: conservation law its scene promises: :func:`freefloat.app.conservation_check.check`).
GOOD = ("completed", "stopped", "refused")
