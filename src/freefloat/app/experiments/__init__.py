"""Experiment kinds, one module each, chosen by a scene's ``kind``.

An experiment module knows how to prepare a scene of its kind, run its loop, summarise it and
draw it (:class:`~freefloat.app.experiments.base.Experiment`); :mod:`freefloat.app.runner` runs
any of them the same way and :mod:`freefloat.app.outputs` writes any outcome. A new kind is one
new module and one line in :data:`EXPERIMENTS`.
"""

from __future__ import annotations

from ...errors import SceneError, did_you_mean
from ..environments import environment_units
from . import capture, detumbling, joint_space, mechanism, two_hand_capture
from .base import Experiment, Outcome, Progress

#: Experiment kinds by the scene kind they run.
EXPERIMENTS: dict[str, Experiment] = {
    e.kind: e for e in (joint_space.EXPERIMENT, detumbling.EXPERIMENT, capture.EXPERIMENT, two_hand_capture.EXPERIMENT,
                        mechanism.EXPERIMENT)
}


def experiment_for(scene) -> Experiment:
    """The experiment that runs ``scene`` (by ``scene.kind``).

    Raises:
        SceneError: for a kind no experiment runs, listing the kinds.
    """
    try:
        return EXPERIMENTS[scene.kind]
    except KeyError:
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
