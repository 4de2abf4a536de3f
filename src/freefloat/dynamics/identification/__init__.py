"""Identification of dynamic parameters by linear least squares on Pinocchio's regressors.

A rigid body's dynamics are linear in its ten inertial parameters (Pinocchio's
``Inertia.toDynamicParameters`` order, :data:`~.parameters.PARAMETER_NAMES`): mass, first moments
``m c`` and the inertia about the body frame's origin. So are a tree's joint torques and its
momentum, which makes identification a linear least-squares problem:

``parameters`` (the tree's parameter vector, by joint), ``regressors`` (the joint-torque
regressor stacked over samples and the momentum regressor about the inertial origin), ``base``
(base parameters, the identifiable combinations, by QR with column pivoting), ``least_squares``
(the estimate with its covariance and confidence intervals), ``excitation`` (Fourier-series
trajectories and their condition number) and ``measurements`` (seeded sensor noise and the
differentiation of measured rates).

May import: :mod:`freefloat.robot`, :mod:`freefloat.errors` and, of the dynamics layer, only
:mod:`freefloat.dynamics.threads` (one BLAS thread around the small dense algebra): identification
reads recorded samples, it runs no simulation.
"""
