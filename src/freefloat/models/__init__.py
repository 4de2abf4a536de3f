"""Dynamics models behind one interface, selectable by name."""

from __future__ import annotations

from ..robot import Robot
from .base import DynamicsModel
from .exact import ExactModel

#: Registry names and one-line descriptions.
MODELS = {"exact": "Pinocchio ABA: the exact reference"}


def make_model(name: str, robot: Robot) -> DynamicsModel:
    """The dynamics model called ``name`` for ``robot``.

    Raises:
        ValueError: for an unknown name, listing the valid ones.
    """
    if name == "exact":
        return ExactModel(robot)
    raise ValueError(f"unknown dynamics model '{name}'; valid: {', '.join(MODELS)}")


__all__ = ["MODELS", "DynamicsModel", "ExactModel", "make_model"]
