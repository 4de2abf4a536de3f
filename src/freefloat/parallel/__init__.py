"""The closed-chain task layer: parallel mechanisms by Orsino's subsystem coupling (thesis
proposal secs 5.3-5.4).

``serial`` (chains from DH parameters or a URDF tree), ``mechanism`` (the coupling, constraints,
forward and inverse dynamics, assembly), ``closed_chain`` (URDF spanning tree + closure file),
``five_bar`` and ``rsu_ppap`` (the two mechanisms), ``three_rrr`` (a planar platform that
turns: angular constraints with P != 0), ``redundancy`` (efforts shared among more actuators
than platform coordinates), ``rsu_ppap_masses`` (its uncertain masses:
plants and gain model), ``platform`` (platform-coordinate dynamics), ``gain_design`` (the
worst-case gain design of any mechanism linear in its parameters), ``gain_feasibility`` (where
that design has a solution), ``identification`` (the parameters identified from measured efforts
through the coupling, and the design's model on the identified intervals), ``sliding_mode`` (the control law, the 5R's gain model, chattering,
printed gains), ``closed_loop`` (a
mechanism and its law wired into the one loop of :mod:`freefloat.dynamics`: the law held over a
control period or evaluated at every stage), ``platform_control`` (circle references), ``sweeps``
(Dask), ``drives`` (a mechanism driven by DC motors: rotors, drive trains, the motor-driven
plant), ``drive_gain_design`` (the worst-case gains with the motors' uncertainty, voltage or
torque input), ``registry`` (mechanisms by name for scenes) and ``free_base`` (a mechanism's tree on a
planar or free base, Pinocchio's ``constraintDynamics`` as its plant, the law in the base frame). No time loop of its own: the plant is
:class:`freefloat.dynamics.plants.CoupledChainPlant`, run by ``dynamics.simulation.run_plant``.

May import: :mod:`freefloat.dynamics` (plants, the loop, the compiled core), :mod:`freefloat.robot`
(builders, conventions), :mod:`freefloat.errors`, :mod:`freefloat.paths`. Not
:mod:`freefloat.space` (a sibling) nor :mod:`freefloat.app`.
"""
