"""Experiment kinds, one module each, chosen by a scene's ``kind``.

An experiment module knows which scenes it takes, how to prepare one, run its loop, summarise it
and draw it (:class:`~freefloat.app.experiments.base.Experiment`); :mod:`freefloat.app.runner`
runs any of them the same way and :mod:`freefloat.app.outputs` writes any outcome. A new kind is
one module (inside the package or a user's) and one ``EXPERIMENTS.register(...)``; a scene's
kind is the registered experiment that takes it, or the one its top-level ``kind`` names
(:func:`freefloat.app.scenes.kinds.kind_of`). The registry itself lives with the scenes, which
read it; importing this package registers the built-in kinds into it.
"""

from __future__ import annotations

from ...errors import SceneError, UnknownName, did_you_mean
from ...registry import Registry
from ..environments import environment_units
from ..scenes import kinds
from . import capture, capture_identification, contact_capture, detumbling, joint_space, mechanism, two_hand_capture
from .base import Experiment, Outcome, Progress

#: Registry of experiment kinds: name -> :class:`Experiment` (``freefloat.EXPERIMENTS``; the one
#: registry of :mod:`freefloat.app.scenes.kinds`, which a scene reads its kind from).
EXPERIMENTS: Registry[Experiment] = kinds.EXPERIMENTS
for _experiment in (joint_space.EXPERIMENT, detumbling.EXPERIMENT, capture.EXPERIMENT, capture_identification.EXPERIMENT,
                    two_hand_capture.EXPERIMENT, mechanism.EXPERIMENT, contact_capture.EXPERIMENT):
    EXPERIMENTS.register(_experiment)


def experiment_for(scene) -> Experiment:
    """The experiment that runs ``scene`` (by ``scene.kind``).

    Raises:
        SceneError: for a kind no experiment runs, listing the kinds (and what ``scene.kind``
            raises: no kind or a wrong named kind).
        InvalidArgument: two registered kinds take the scene.
    """
    try:
        return EXPERIMENTS[scene.kind]
    except UnknownName:
        raise SceneError(f"scene '{scene.name}': no experiment runs kind '{scene.kind}'"
                         f"{did_you_mean(scene.kind, EXPERIMENTS, 'kinds')}") from None


def summary_units(scene) -> dict[str, str]:
    """The unit of each summary key a run of ``scene`` may have: its experiment's
    (:attr:`Experiment.units`), its environment entries' (``EnvironmentSpec.units``) and the
    conservation check's (:mod:`..conservation_check`)."""
    from ..conservation_check import UNITS

    return {**experiment_for(scene).units, **environment_units(getattr(scene, "environment", ())), **UNITS}


__all__ = ["EXPERIMENTS", "Experiment", "Outcome", "Progress", "experiment_for", "summary_units"]

from ...lazy import lazy_modules  # noqa: E402

__getattr__ = lazy_modules(__name__)  # its modules, imported on first use as attributes
