"""Controllers of free-floating robots: quintic joint references, joint-space computed torque
on any dynamics model, the guarded inverse E-GJM, task-space computed torque, detumbling, and the
identification manoeuvre (``excitation``: computed torque on a Fourier-series trajectory).

``Controller`` (the loop's interface) and ``joint_space_dynamics`` (the exact H*, c*) live in
:mod:`freefloat.dynamics`; they are re-exported here for convenience.
"""

from ...dynamics.models.exact import joint_space_dynamics
from ...dynamics.simulation import Controller
from .computed_torque import ComputedTorque
from .trajectory import QuinticTrajectory

__all__ = ["Controller", "ComputedTorque", "QuinticTrajectory", "joint_space_dynamics"]
