"""The dynamics layer: what a free-floating robot does, exactly and by the dissertation's models.

``gjm`` (the hand-built GJM: H0, H0m, Hm, H*, E-GJM, derivatives, momenta), ``reference``
(Pinocchio's counterparts), ``verify`` (the cross-check of the two), ``models`` (dynamics models
selectable by name, Pinocchio's ABA the exact one), ``integrators`` (on the configuration Lie
group), ``wrenches`` (external wrenches on links), ``simulation`` (the zero-order-hold loop and
its :class:`~freefloat.dynamics.simulation.Controller` interface), ``telemetry``, ``metrics``,
``balance`` (momentum and energy against the impulse and work of external wrenches),
``stability`` (the largest stable step, by bisection), ``friction`` (joint friction, viscous and
regularised Coulomb), ``motors`` (DC motors and their data files; a plant driven by them is
``plants.motor_driven``, a robot tree as a plant ``plants.tree``), ``voltage_drive`` (a torque
law's efforts as motor voltages) and ``sensors`` (noise, bias, delay and sampling on what a law
reads, and the momentum estimated from it: ``Sensed(controller, sensors)``).

May import: :mod:`freefloat.robot`, :mod:`freefloat.errors`, :mod:`freefloat.paths`.
"""

# The compiled loop (``_sim``) is linked to the pin wheel's libpinocchio_default; importing
# pinocchio loads that library, which is how an editable install's ``_sim`` finds it.
import pinocchio as _pinocchio  # noqa: E402, F401
