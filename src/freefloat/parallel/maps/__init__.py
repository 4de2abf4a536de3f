"""Maps of a closed-chain mechanism: workspace and its boundary, type I and type II singularity
loci in task space and in actuated-joint space, assembly and working modes (issue 21 item 5),
for any :class:`~freefloat.parallel.mechanism.ParallelMechanism` without redundancy.

Modules: ``jacobians`` (the two partitions of the constraint Jacobian, Gosselin & Angeles'
types), ``solve`` (batched Newton from many starts), ``modes`` (working and assembly modes),
``five_bar_exact`` (the 5R's workspace in closed form), ``grids`` (every mode over a grid of
platform points or actuated joints, the workspace and its boundary) and ``loci`` (points on the
singularity loci, refined by bisection). The atlas kind ``mechanism``
(:mod:`freefloat.app.atlas.mechanism_maps`) runs them over a grid and draws them.

May import: :mod:`freefloat.parallel` (the mechanisms), :mod:`freefloat.errors`; nothing above.
"""

from ...lazy import lazy_modules  # noqa: E402

__getattr__ = lazy_modules(__name__)  # its modules, imported on first use as attributes
