"""Worst-case sliding-mode gains for a mechanism whose actuators are DC motors with uncertain
parameters (thesis proposal sec 9, item 10): the design of eqs 154-170
(:mod:`~freefloat.parallel.gain_design`) extended to the drives.

The law is eq 153 on a nominal model that includes the rotors (armature ``N^2 J^_m``) and the
drive trains' friction ``f^ = b^ qdot_a + c^ tanh(qdot_a / v_s)`` on the actuated joints; its
efforts ``tau_d = B^-1 (h^ + H^ (sigma - k f(s)))`` (``B = C^T U``) are driven through the
motors by :class:`~freefloat.dynamics.voltage_drive.VoltageDrive`, whose integral action brings
the current to ``i_d = tau_d / (N k^_t)`` whatever the resistance and back-EMF errors, so with the
current at rest of its loop the actuators give ``rho tau_d``, ``rho = k_t / k^_t`` (per actuator),
and with the true friction ``f`` the platform moves by

.. math::
    H \\ddot q^\\# + v_M + g_M = \\Gamma (\\hat v_M + \\hat g_M + \\hat H a)
        + B (\\beta \\circ W \\dot q^\\# + \\gamma \\circ t), \\qquad
    \\Gamma = B\\,\\mathrm{diag}(\\rho)\\,B^{-1},

``a = sigma - k f(s)``, ``W = U^T C`` (the actuated joints' rates ``qdot_a = W qdot#``),
``beta = rho b^ - b``, ``gamma = rho c^ - c``, ``t = tanh(qdot_a / v_s)`` in [-1, 1].
Against eq 155 this replaces ``Delta = H^-1 H^ - 1`` by ``H^-1 Gamma H^ - 1``, ``delta_0`` by
``H^-1 (Gamma g^ - g)`` plus ``|H^-1 B| |gamma|``, ``delta_ij`` by ``H^-1 (Gamma delta^_ij -
delta_ij)``, and adds a term linear in the rates, ``delta_i = H^-1 B diag(beta) W e_i``, so the
gain of eq 167 gains ``sum_i n_i |qdot#_i|`` (``n_i = (1 - |Delta|_max)^-1 |delta_i|_max``).

The rotors' inertias enter H like the links' parameters (``H = sum_k pi_k H_k + sum_j N_j^2
J_m,j H_a,j``): they join the vertex enumeration. ``rho``, ``beta`` and ``gamma`` are taken over
their boxes, computed from the vertices of each motor's torque constant and friction (each of
them monotonic in every one of those parameters); ``Delta``, ``delta_0``, ``delta_ij`` and
``delta_i`` are affine in them, so their largest absolute values over the boxes are exact (no
enumeration). The resistance, inductance and back-EMF constant do not enter: they act only
while the current loop settles (its lag is left out, as the sampling and the boundary layer are:
the runs measure them); the design assumes the current at rest of its loop, a loop much faster
than the mechanism. (Without the integral action the static current is off by ``L^ omega_c /
(L^ omega_c + R - R^)`` and by a back-EMF term: with 15 % errors on the 5R that made ``rho``
range over [0.76, 1.30] at 5000 1/s and the design infeasible along sec 5.6's circle, spectral
radius 1.20.) ``voltage=False`` is torque input through ideal actuators (``rho = 1``) on the same
motorised mechanism: only the rotors and the friction are uncertain then.
"""

from __future__ import annotations

import functools
import itertools
from dataclasses import dataclass, field, replace
from typing import Any, NamedTuple

import numpy as np

from ..dynamics.motors import DCMotor
from . import gain_design
from .gain_design import SlidingModeGains, WorstCase
from .mechanism import ParallelMechanism
from .platform import platform_dynamics, quadratic_coefficients


class DriveBounds(NamedTuple):
    """Per-actuator intervals (2, k) (rows: lower, upper) of ``rho`` (effort per effort asked),
    ``beta`` (N m s/rad or N s/m, on the joint rate) and ``gamma`` (N m or N, on ``tanh``)."""

    rho: np.ndarray
    beta: np.ndarray
    gamma: np.ndarray


def drive_bounds(motors: DCMotor, relative: dict[str, float], voltage: bool) -> DriveBounds:
    """The intervals of ``rho``, ``beta``, ``gamma`` over the vertices of each motor's torque
    constant, viscous and Coulomb friction (``relative`` half-widths about ``motors``), for voltage
    input through :class:`~freefloat.dynamics.voltage_drive.VoltageDrive` or, with ``voltage``
    False, torque input (``rho = 1``)."""
    names = ("torque_constant", "viscous", "coulomb")
    nominal = {n: np.atleast_1d(np.asarray(getattr(motors, n), float)) for n in names}
    rows = []
    for signs in itertools.product((-1.0, 1.0), repeat=len(names)):
        true = {n: nominal[n] * (1.0 + s * relative.get(n, 0.0)) for n, s in zip(names, signs)}
        rho = true["torque_constant"] / nominal["torque_constant"] if voltage else np.ones(len(motors))
        rows.append((rho, rho * nominal["viscous"] - true["viscous"], rho * nominal["coulomb"] - true["coulomb"]))
    values = np.array(rows)  # (vertices, 3, k)
    lo, hi = values.min(axis=0), values.max(axis=0)
    return DriveBounds(*(np.stack((lo[i], hi[i])) for i in range(3)))


def largest_over_box(constant: np.ndarray, slopes: np.ndarray, box: np.ndarray) -> np.ndarray:
    """``max |constant + sum_j slopes[..., j] x_j|`` over ``x`` in the box ``box`` (2, k), element
    by element (an affine function's extremes over a box sit at its vertices): (...)."""
    low, high = slopes * box[0], slopes * box[1]
    top = constant + np.maximum(low, high).sum(axis=-1)
    bottom = constant + np.minimum(low, high).sum(axis=-1)
    return np.maximum(np.abs(top), np.abs(bottom))


@dataclass(frozen=True, eq=False)
class DrivenModel:
    """A mechanism's :class:`~freefloat.parallel.gain_design.LinearParameterModel` with a DC motor
    on each actuator: its parameters and the rotors' inertias ``J_m`` (k) are the vertex
    parameters, ``pi = [pi_mech; N^2 J_m]``; the drives' other parameters are bounded by
    :func:`drive_bounds`.

    Attributes:
        mechanical: the mechanism's model (``FiveBarModel``, ``RsuPpapModel``: with its nominal
            rigid ``mechanism``).
        motors: the motors' nominal parameters (k,), actuator order.
        relative: relative half-widths of the motor parameters (the motor file's ``uncertainty``).
        voltage: True for voltage input through the drive, False for torque input (ideal
            actuators acting on the same motorised mechanism).
    """

    mechanical: Any
    motors: DCMotor
    relative: dict = field(default_factory=dict)
    voltage: bool = True

    @property
    def p(self) -> int:
        return self.mechanical.p

    @property
    def names(self) -> tuple[str, ...]:
        return tuple(self.mechanical.names) + tuple(f"rotor_inertia[{j}]" for j in range(len(self.motors)))

    @property
    def nominal(self) -> np.ndarray:
        return np.concatenate((self.mechanical.nominal, np.atleast_1d(self.motors.rotor_inertia)))

    @property
    def uncertainty(self) -> np.ndarray:
        rotor = np.atleast_1d(self.motors.rotor_inertia) * self.relative.get("rotor_inertia", 0.0)
        return np.concatenate((self.mechanical.uncertainty, rotor))

    @property
    def mechanism(self) -> ParallelMechanism:
        """The nominal rigid mechanism (no rotors, no friction)."""
        return self.mechanical.mechanism

    def linear_parameters(self, theta: np.ndarray) -> np.ndarray:
        """``[pi_mech(theta_mech); N^2 J_m]``."""
        r = len(self.mechanical.names)
        gear = np.atleast_1d(self.motors.gear_ratio)
        return np.concatenate((self.mechanical.linear_parameters(theta[:r]), gear**2 * theta[r:]))

    def assemble(self, point: np.ndarray) -> np.ndarray:
        return self.mechanical.assemble(point)

    @functools.cached_property
    def bounds(self) -> DriveBounds:
        return drive_bounds(self.motors, self.relative, self.voltage)

    @functools.cached_property
    def unit_rotors(self) -> tuple[ParallelMechanism, ...]:
        """The rigid mechanism with a unit armature on one actuated joint, for each actuator."""
        mech, out = self.mechanism, []
        for index in mech.actuated:
            chains, start = list(mech.chains), mech.p
            for c, chain in enumerate(chains):
                if start <= index < start + chain.dof:
                    armature = np.zeros(chain.dof)
                    armature[index - start] = 1.0
                    chains[c] = replace(chain, armature=armature)
                start += chain.dof
            out.append(replace(mech, chains=tuple(chains)))
        return tuple(out)

    def coefficients(self, q: np.ndarray) -> tuple[np.ndarray, np.ndarray, dict]:
        """The mechanical coefficients of H, g_M, delta_ij, then one more per rotor (a unit
        armature on its joint: none in g_M)."""
        H_c, g_c, quad_c = self.mechanical.coefficients(q)
        H0 = platform_dynamics(self.mechanism, q, np.zeros(self.p))[0]
        quad0 = quadratic_coefficients(self.mechanism, q)
        H_a, quad_a = [], []
        for mech in self.unit_rotors:
            H_a.append(platform_dynamics(mech, q, np.zeros(self.p))[0] - H0)
            quad_a.append({key: value - quad0[key] for key, value in quadratic_coefficients(mech, q).items()})
        return (np.concatenate((H_c, H_a)), np.concatenate((g_c, np.zeros((len(H_a), self.p)))),
                {key: np.concatenate((c, [row[key] for row in quad_a])) for key, c in quad_c.items()})


def point_worst_case(model: DrivenModel, q: np.ndarray, extremes: np.ndarray) -> WorstCase:
    """The worst cases at one assembled pose q (n_q,) over the vertex parameter sets ``extremes``
    (V, r) and the drives' boxes (module docstring)."""
    H_c, g_c, quad_c = model.coefficients(q)
    pi_hat = model.linear_parameters(model.nominal)
    H_hat, g_hat = np.tensordot(pi_hat, H_c, 1), pi_hat @ g_c
    quad_hat = {key: pi_hat @ c for key, c in quad_c.items()}
    mech = model.mechanism
    C = mech.velocity_map(q)
    B, W = C.T @ mech.selection(), C[mech.actuated]
    Binv = np.linalg.inv(B)
    p, bounds = model.p, model.bounds
    pis = np.array([model.linear_parameters(theta) for theta in extremes])
    Hinv = np.linalg.inv(np.einsum("vl,lij->vij", pis, H_c))              # (V, p, p)
    HB = Hinv @ B                                                            # (V, p, k)
    # Gamma X = sum_j rho_j B_j (B^-1 X)_j: slopes of H^-1 Gamma X on rho (V, ..., k)
    Delta = largest_over_box(-np.eye(p), np.einsum("vrj,jc->vrcj", HB, Binv @ H_hat), bounds.rho).max(axis=0)
    affine = lambda x, true: largest_over_box(-np.einsum("vrc,vc->vr", Hinv, true), HB * (Binv @ x), bounds.rho)
    gamma = np.abs(bounds.gamma).max(axis=0)
    delta0 = (affine(g_hat, pis @ g_c) + np.abs(HB) @ gamma).max(axis=0)
    deltaij = {key: affine(quad_hat[key], pis @ c).max(axis=0) for key, c in quad_c.items()}
    deltai = {i: largest_over_box(np.zeros(p), HB * W[:, i], bounds.beta).max(axis=0) for i in range(p)}
    return WorstCase(Delta, delta0, deltaij, deltai)


def worst_case(model: DrivenModel, points: np.ndarray, sample: int | None = None, seed: int = 0) -> WorstCase:
    """The worst cases over ``points`` (N, p), the vertices of the parameter box
    (:func:`~freefloat.parallel.gain_design.vertices`) and the drives' boxes.

    Raises:
        FreefloatError: as :func:`freefloat.parallel.gain_design.worst_case`.
    """
    return gain_design.worst_case(model, points, sample, seed, point_worst_case)


def design_gains(model: DrivenModel, points: np.ndarray, eta: float = 20.0, sample: int | None = None,
                 seed: int = 0) -> SlidingModeGains:
    """Worst-case gains (eqs 155-170 with the drives' terms) over ``points`` (N, p)."""
    return gain_design.gains_from_worst_case(worst_case(model, points, sample, seed), eta, points)
