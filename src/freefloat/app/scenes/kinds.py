"""A scene's kind: the one registered experiment kind that takes it, or the one its top-level
``kind`` names; and the scene sections an experiment kind declares (``sections``: a robot scene's
own tables that a user's kind reads, validated like the built-in sections).

The registry of experiment kinds lives here, below the experiments that fill it, because a scene
reads its kind from it while every experiment module imports the scenes:
:mod:`freefloat.app.experiments` registers the built-in kinds when it is imported (as
``freefloat.simulate``, the runner, ``batch`` and the command line do before they read a kind),
and a user's module registers its own into the same registry (``freefloat.EXPERIMENTS``).
"""

from __future__ import annotations

from typing import Any, Protocol

from ...errors import InvalidArgument, SceneError, did_you_mean
from ...registry import Registry
from .fields import Rules, parse_section


class SceneKind(Protocol):
    """What a scene's kind is read from (an :class:`~freefloat.app.experiments.base.Experiment`).

    Attributes:
        name: the kind (``scene.kind``).
        scenes: which scenes it takes, in words (for the message refusing a named kind).
        sections: the scene sections it reads besides the built-in ones: name -> the frozen
            dataclass whose fields are the section's keys (a kind never takes a scene with a
            section it does not read).
    """

    name: str
    scenes: str
    sections: dict[str, type]

    def takes(self, scene: Any) -> bool:
        """Whether this kind runs ``scene`` (read from its sections, never from its ``kind``)."""
        ...


#: Registry of experiment kinds: name -> experiment (filled by :mod:`freefloat.app.experiments`,
#: imported at the first lookup, and by plug-ins; exported as ``freefloat.EXPERIMENTS``).
EXPERIMENTS: Registry[Any] = Registry("experiment kind", builtins="freefloat.app.experiments")


def kind_of(scene: Any) -> str:
    """The experiment kind of ``scene``: the one its ``named_kind`` names (top-level ``kind``),
    which must take it, or else the one registered kind whose ``takes(scene)`` is true (among
    the kinds that read every section of ``scene.sections``).

    Raises:
        SceneError: a named kind not registered (with the nearest), or one that does not take the
            scene (saying which scenes it takes and which kind does take this one); no kind takes
            the scene (listing the kinds).
        InvalidArgument: two registered kinds take the scene (a programming error in one of
            them: each scene must be taken by exactly one), naming both.
    """
    where = f"{scene.source}: " if getattr(scene, "source", None) else f"scene '{scene.name}': "
    named = getattr(scene, "named_kind", "")
    own = set(getattr(scene, "sections", {}))
    takers = [name for name, kind in EXPERIMENTS.items() if own <= set(kind.sections) and kind.takes(scene)]
    if named:
        if named not in EXPERIMENTS:
            raise SceneError(f"{where}'kind' is {named!r}{did_you_mean(named, EXPERIMENTS, 'experiment kinds')}")
        if named not in takers:
            taken = f"; this scene is a {' or '.join(repr(t) for t in takers)} scene" if takers else ""
            raise SceneError(f"{where}'kind' is {named!r}, but that experiment takes {EXPERIMENTS[named].scenes}"
                             f"{taken}")
        return named
    if len(takers) > 1:
        raise InvalidArgument(f"experiment kinds {' and '.join(repr(t) for t in takers)} both take scene "
                              f"'{scene.name}': each scene must be taken by exactly one kind (a programming error in "
                              "their takes); a scene may name its kind with a top-level kind = \"...\"")
    if not takers:
        raise SceneError(f"{where}no experiment kind takes this scene"
                         f"{did_you_mean('', EXPERIMENTS, 'experiment kinds')}; name one with a top-level "
                         "kind = \"...\"")
    return takers[0]


def kind_sections() -> dict[str, type]:
    """The scene sections the registered experiment kinds declare: name -> settings dataclass."""
    return {name: cls for kind in EXPERIMENTS.values() for name, cls in kind.sections.items()}


def parse_kind_sections(where: str, raw: dict[str, Any], rules: Rules, builtin: set[str]) -> dict[str, Any]:
    """The tables of ``raw`` (a scene file's top level) that a registered experiment kind
    declares, each parsed into its settings dataclass (unknown key, type, ``rules``).

    Args:
        builtin: the scene's own top-level keys, which no kind may declare.

    Raises:
        SceneError: naming the section's key that is wrong.
        InvalidArgument: a kind declares a built-in key as its section (naming both).
    """
    for kind in EXPERIMENTS.values():
        for name in set(kind.sections) & builtin:
            raise InvalidArgument(f"experiment kind '{kind.name}' declares the section '{name}', a built-in key of "
                                  "the scene; rename its section")
    return {name: parse_section(where, name, cls, raw[name], rules) for name, cls in kind_sections().items()
            if name in raw}


class Kinded:
    """A scene whose ``kind`` is read from the registered experiment kinds (:func:`kind_of`);
    ``named_kind`` is its top-level ``kind`` ("" when it leaves the choice to them)."""

    named_kind: str

    @property
    def kind(self) -> str:
        """The experiment kind that runs this scene (:func:`kind_of`)."""
        return kind_of(self)
