"""``freefloat bench``: freefloat's integrators against MuJoCo's, side by side in one process.

``mjcf`` (MJCF from a loaded robot, inertia balancing), ``mujoco_state`` (the two state
conventions), ``scenes`` (tumbling scenes from a seeded state), ``methods`` (each integrator as a
run), ``sweep`` (wall time and errors per point), ``summary`` (cheapest method per accuracy band)
and ``report`` (the output folder). MuJoCo is an optional extra (``pip install -e ".[bench]"``);
only ``methods.mujoco_run`` imports it.
"""
