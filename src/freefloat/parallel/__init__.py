"""The closed-chain task layer: parallel mechanisms by Orsino's subsystem coupling (thesis
proposal secs 5.3-5.4).

``serial`` (chains from DH parameters or a URDF tree), ``mechanism`` (the coupling, constraints,
forward and inverse dynamics, assembly), ``closed_chain`` (URDF spanning tree + closure file),
``five_bar`` and ``rsu_ppap`` (the two mechanisms), ``platform`` (platform-coordinate dynamics),
``sliding_mode`` (the control law, gain design, chattering), ``held_control`` (the closed loop
with the law held over a control period or evaluated at every stage), ``platform_control`` (circle
references, printed gains), ``sweeps`` (Dask) and ``registry`` (mechanisms by name for scenes).

May import: :mod:`freefloat.robot` (builders, conventions), :mod:`freefloat.errors`,
:mod:`freefloat.paths`. Not :mod:`freefloat.space` (a sibling) nor :mod:`freefloat.app`.
"""
