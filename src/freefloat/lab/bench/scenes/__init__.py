"""The scenes of the race against MuJoCo (``freefloat bench SCENE``), one registry: :data:`SCENES`.

Each module builds its scenes as :class:`~..race.scene.BenchScene`: ``free_floating`` (robots on a
free base: ``tumbling`` torque-free with non-zero momentum, ``controlled`` under computed torque,
``detumbling`` after a capture, with ``methods``: each package's integrators as runs),
``mechanisms`` (closed chains, with ``mechanism_plants``), ``floating_mechanisms`` (closed chains
on a moving base) and ``two_hand_capture`` (the post-grasp phase of a two-hand capture).

A new scene is one entry here and its factory. The registry imports no scene module: the
command's help lists the scenes without loading them.
"""

from __future__ import annotations

import importlib
from dataclasses import dataclass
from typing import TYPE_CHECKING

from ....registry import Registry

if TYPE_CHECKING:
    from ..race.scene import BenchScene


@dataclass(frozen=True)
class SceneEntry:
    """One scene of the race.

    Attributes:
        name: the ``SCENE`` argument (file names, ``bench.json``'s keys).
        note: one line saying what runs and what differs from the document or URDF.
        module: its module in this package.
        factory: the module's ``factory(name, duration, quick)`` that builds it, with a fourth
            argument ``seed`` if :attr:`seeded`.
        seeded: whether the factory takes the bench's seed (the tumbling scenes' initial state).
        default: swept by a bench that names no scene.
    """

    name: str
    note: str
    module: str
    factory: str
    seeded: bool = False
    default: bool = True

    def build(self, duration: float | None, quick: bool, seed: int) -> BenchScene:
        """The scene, its module imported now (``duration``: None for the scene's own)."""
        factory = getattr(importlib.import_module(f"{__name__}.{self.module}"), self.factory)
        return factory(self.name, duration, quick, seed) if self.seeded else factory(self.name, duration, quick)


#: Every scene, in the order a bench sweeps them.
SCENES: Registry[SceneEntry] = Registry("bench scene")

for _entry in (
    SceneEntry("four_arm", "four-arm robot with a free base; inertias balanced (MuJoCo refuses the URDF's)",
               "free_floating", "free_floating_scene", seeded=True),
    SceneEntry("dual_arm", "UR5 dual-arm satellite", "free_floating", "free_floating_scene", seeded=True),
    SceneEntry("controlled", "four-arm robot (balanced, free base), computed torque held over 1 ms, the default "
                             "task's quintic; also on its planar base", "free_floating", "free_floating_scene",
               seeded=True),
    SceneEntry("detumbling", "two-arm robot (balanced) after capture (500 N m impulses on both arms, sec 5.3 "
                             "scenario 4), free base, detumbling control held over 1 ms; also on its planar base",
               "free_floating", "free_floating_scene", seeded=True),
    SceneEntry("five_bar", "5R (scene five_bar_sliding_mode): sliding mode (eq 153, eq 187's gains) on the nominal "
                           "model, plant 15 % off, circle of eq 189; law held over 0.1 ms (the scene file's step)",
               "mechanisms", "mechanism_scene"),
    SceneEntry("rsu_ppap", "2RSU+PPaP (scene rsu_ppap_computed_torque, assumed geometry): computed torque (eq 190) "
                           "on an exact model, 3 cm circle at 1 Hz; law held over 1 ms (the scene file's step)",
               "mechanisms", "mechanism_scene"),
    SceneEntry("five_bar_free_base", "5R on a planar free base (5 kg), zero gravity, sliding mode (eq 187's gains, "
                                     "plant 15 % off) in the base frame; law held over 0.1 ms (the scene file's step)",
               "floating_mechanisms", "floating_mechanism_scene", default=False),
    SceneEntry("rsu_ppap_free_base", "2RSU+PPaP on a free base (50 kg), zero gravity, computed torque (eq 190) in the "
                                     "base frame; law held over 1 ms (the scene file's step)",
               "floating_mechanisms", "floating_mechanism_scene", default=False),
    SceneEntry("capture_two_hands_satellite", "UR5 dual-arm satellite just after both hands grasped a 50 kg box "
                                              "spinning at 11.5 deg/s (arms bent): the merged robot closed by a weld, "
                                              "the box detumbled through the loop (kd 20 1/s, squeeze 20 N, "
                                              "Baumgarte 20 1/s); law held over 1 ms",
               "two_hand_capture", "two_hand_capture_scene", default=False),
):
    SCENES.register(_entry)


def notes(module: str) -> dict[str, str]:
    """Name -> note of the scenes built by ``module`` (a module of this package)."""
    return {entry.name: entry.note for entry in SCENES.values() if entry.module == module}

from ....lazy import lazy_modules  # noqa: E402

__getattr__ = lazy_modules(__name__)  # its modules, imported on first use as attributes
