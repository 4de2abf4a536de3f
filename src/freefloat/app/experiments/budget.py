"""What a run will cost, estimated before it starts: a run that would not fit in memory or would
take more than a day is refused with the estimate and the scene keys that set it."""

from __future__ import annotations

import time
from collections.abc import Callable, Hashable

from ...errors import SceneError
from ...robot.urdf_checks import MEMORY_SHARE, usable_memory

#: Longest run accepted, s of wall-clock time.
MAX_SECONDS = 24 * 3600.0


def seconds_per_call(call: Callable[[], object], repeats: int = 5) -> float:
    """Median wall-clock time of ``call()``, s (one warm-up call first)."""
    call()
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        call()
        times.append(time.perf_counter() - start)
    return sorted(times)[len(times) // 2]


#: :func:`seconds_per_call_once`'s measurements in this process, by key.
_MEASURED: dict[Hashable, float] = {}


def seconds_per_call_once(key: Hashable, call: Callable[[], object]) -> float:
    """:func:`seconds_per_call` of ``call``, measured once per process for each ``key`` (what the
    cost depends on: a model's kind and structure, not its masses): a batch's runs of one robot
    pay for it once."""
    if key not in _MEASURED:
        _MEASURED[key] = seconds_per_call(call)
    return _MEASURED[key]


def check_budget(scene_name: str, memory_bytes: float, seconds: float, keys: str) -> None:
    """Refuse a run estimated to need more memory than it may take (``usable_memory``) or
    more than :data:`MAX_SECONDS`.

    Raises:
        SceneError: naming the scene, the keys that set the size (``keys``) and the estimate.
    """
    available = usable_memory()
    if memory_bytes > available:
        raise SceneError(f"scene '{scene_name}': {keys} ask for a run that needs about {memory_bytes / 1e9:.3g} GB "
                         f"of telemetry, more than {available / 1e9:.3g} GB ({MEMORY_SHARE:.0%} of this machine's "
                         "memory); shorten it or record fewer samples")
    if seconds > MAX_SECONDS:
        raise SceneError(f"scene '{scene_name}': {keys} ask for a run estimated at {seconds / 3600:.3g} h "
                         f"(more than {MAX_SECONDS / 3600:.0f} h); shorten it or use fewer evaluations")
