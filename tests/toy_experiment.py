"""A toy experiment kind written outside freefloat, as a user's module would be: ``coast`` runs a
torque-free robot scene as ``joint_space`` does and reads a section of its own, ``[coast]``,
whose ``label`` it writes into the summary. tests/test_experiments.py registers it; it must run
through freefloat.simulate with no other edit."""

from __future__ import annotations

from dataclasses import dataclass

from freefloat.app.experiments import Experiment, joint_space
from freefloat.app.scenes import Scene


@dataclass(frozen=True)
class CoastSettings:
    """``[coast]``: ``label``, a text the run writes into its summary as ``coast_label``."""

    label: str = "coasting"


def takes(scene: object) -> bool:
    """A torque-free robot scene: no ``[target]``, no task, no controller."""
    return (isinstance(scene, Scene) and scene.target is None and scene.task.kind == "none"
            and scene.controller.kind == "none")


def run(setup, progress=None, checkpoint=None):
    """joint_space's run, with the scene's ``[coast] label`` in the summary."""
    outcome = joint_space.run(setup, progress, checkpoint)
    outcome.summary["coast_label"] = setup.scene.sections.get("coast", CoastSettings()).label
    return outcome


EXPERIMENT = Experiment("coast", "a robot coasting torque-free (a toy kind)", "torque-free robot scenes", takes,
                        joint_space.prepare, joint_space.EXPERIMENT.steps, run, units={"coast_label": ""},
                        sections={"coast": CoastSettings})
