"""``freefloat bench``: speed against accuracy, freefloat side by side with MuJoCo in one process.

``scene`` (what a bench scene is: :class:`~.scene.BenchScene`, :class:`~.scene.Method`);
``free_floating`` (the free-floating scenes and what each sweeps) built on ``scenes`` (tumbling),
``controlled`` (computed torque) and ``detumbling`` (after a capture), with ``methods`` (each
package's integrators as runs), ``mjcf``, ``mujoco_state`` and ``mujoco_wrenches`` (the robot, its
state and its wrenches in MuJoCo's terms); ``mechanisms`` (the closed chains) with
``mechanism_plants``, ``mechanism_mjcf`` and ``mechanism_mujoco``; ``sweep`` (wall time and errors
per point), ``summary`` (cheapest method per accuracy band), ``chart`` (work against precision) and
``report`` (the output folder); ``options`` (what the command asks of every suite) and ``suites``
(``freefloat bench --suite``: these scenes and the other benchmarks, one registry). MuJoCo is an
optional extra (``pip install -e ".[bench]"``); only the MuJoCo runs import it.
"""
