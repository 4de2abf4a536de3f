"""The space-robot task layer: control, capture and detumbling of free-floating robots.

``control`` (quintic references, joint-space and task-space computed torque on any dynamics model,
the guarded inverse E-GJM, the detumbling controller), ``detumbling`` (the post-capture solver,
eqs 115-120, 134), ``capture`` (exact grasp of a tumbling target, the merged robot),
``target_identification`` (the captured target's mass, CoM and inertia from the motion after the
grasp, by momentum conservation), ``after_capture`` (the identification manoeuvre, detumbling on
a believed model), ``planning`` (the pre-capture approach: reaction null space, minimum norm,
optimised), ``force_propagation`` (end-effector wrenches -> joint torques) and ``orbit`` (the
freely falling frame of a circular orbit: tidal gravity, gravity gradient, the LVLH frame).

May import: :mod:`freefloat.dynamics`, :mod:`freefloat.robot`, :mod:`freefloat.errors`,
:mod:`freefloat.paths`. Not :mod:`freefloat.parallel` (a sibling) nor :mod:`freefloat.app`.
"""

from ..lazy import lazy_modules  # noqa: E402

__getattr__ = lazy_modules(__name__)  # its modules, imported on first use as attributes
