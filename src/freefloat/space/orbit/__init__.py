"""In orbit: a robot floating in the freely falling frame of a circular reference orbit (issue 39
item 1).

``reference`` (the circular orbit about a spherical Earth, the LVLH (Hill) frame, the
Clohessy-Wiltshire closed form), ``field`` (:class:`OrbitField`: the exact tidal gravity on every
body and the gravity-gradient torque on its inertia, a wrench field ``forces(t, q, v)`` /
``wrench(t, q, v)``), ``lvlh`` (a run reported in the LVLH frame), ``propagation`` (time-dependent
fields integrated with their exact stage times), ``libration`` (a rigid satellite's pitch
libration, closed form and measured) and ``summary`` (what a run in orbit adds to its summary: the
``orbit`` environment's ``summarise``). Equations, frames and measured numbers: docs/orbit.md.
"""

from .field import OrbitField, orbit_field
from .lvlh import LvlhTrack, base_in_lvlh, free_flyer_state, in_lvlh, root_in_lvlh
from .reference import EARTH_MU, EARTH_RADIUS, CircularOrbit, OrbitSettings, clohessy_wiltshire

__all__ = ["EARTH_MU", "EARTH_RADIUS", "CircularOrbit", "LvlhTrack", "OrbitField", "OrbitSettings", "base_in_lvlh",
           "clohessy_wiltshire", "free_flyer_state", "in_lvlh", "orbit_field", "root_in_lvlh"]

from ...lazy import lazy_modules

__getattr__ = lazy_modules(__name__)  # its modules, imported on first use as attributes
