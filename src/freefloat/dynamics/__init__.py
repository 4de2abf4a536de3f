"""The dynamics layer: what a free-floating robot does, exactly and by the dissertation's models.

``gjm`` (the hand-built GJM: H0, H0m, Hm, H*, E-GJM, derivatives, momenta), ``reference``
(Pinocchio's counterparts), ``verify`` (the cross-check of the two), ``models`` (dynamics models
selectable by name, Pinocchio's ABA the exact one), ``integrators`` (on the configuration Lie
group), ``wrenches`` (external wrenches on links), ``simulation`` (the zero-order-hold loop and
its :class:`~freefloat.dynamics.simulation.Controller` interface), ``telemetry``, ``metrics``,
``balance`` (momentum and energy against the impulse and work of external wrenches) and
``stability`` (the largest stable step, by bisection).

May import: :mod:`freefloat.robot`, :mod:`freefloat.errors`, :mod:`freefloat.paths`.
"""

# The compiled loop (``_sim``) is linked to the pin wheel's libpinocchio_default; importing
# pinocchio loads that library, which is how an editable install's ``_sim`` finds it.
import pinocchio as _pinocchio  # noqa: E402, F401
