"""Simulated measurements: seeded sensor noise on q, v and efforts, and accelerations from the
measured rates.

Noise is white and Gaussian, drawn from ``numpy.random.default_rng(seed)``, its standard
deviation per channel a ``level`` (e.g. 0.01 for "1 %") of that channel's size over the record:
the RMS for rates and efforts, the standard deviation of the displacement for positions
(configurations are perturbed in the tangent space, ``q (+) dq`` by ``pinocchio.integrate``, so
a base quaternion stays a unit quaternion). A channel that never moves gets no noise.

Accelerations of a measured record come from a Savitzky-Golay filter (a local cubic fitted over
``window`` samples, its derivative at the centre; zero phase, Savitzky and Golay 1964): it
differentiates the noise too, about ``sigma_v sqrt(12 / window^3) / dt`` for a line fit, and
correlates neighbouring samples, so decimate the record by ``window`` before least squares
assumes independent errors.

The same local fit's value at the centre smooths a record (:func:`smooth`,
:func:`smooth_configurations`, which fits in the tangent space at each centre sample), taken
every ``window`` samples so that the smoothed samples share no raw sample: their noise stays
independent, with its variance cut by the fit (to about ``2.25 / window`` of the raw for a cubic
over many samples). That matters when the noise enters the regressor (q and v): least squares on
noisy regressors is biased towards zero by about the noise-to-signal power ratio (errors in
variables), which the smoothing cuts as much, while the estimate's spread is unchanged (fewer
samples, each less noisy).
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import scipy.signal

from ...errors import BadShape, InvalidArgument


def channel_scale(x: np.ndarray, positions: bool = False) -> np.ndarray:
    """Size of each channel of a record (N, c) (c,): its RMS, or with ``positions`` its standard
    deviation (how far it moves about its mean)."""
    x = np.asarray(x, float)
    return x.std(axis=0) if positions else np.sqrt(np.mean(x**2, axis=0))


def noisy(x: np.ndarray, level: float, rng: np.random.Generator, scale: np.ndarray | None = None) -> np.ndarray:
    """``x`` (N, c) plus noise of standard deviation ``level`` times ``scale`` (c,) per channel
    (default: :func:`channel_scale` of x, RMS)."""
    x = np.asarray(x, float)
    scale = channel_scale(x) if scale is None else np.asarray(scale, float)
    return x + rng.normal(size=x.shape) * (level * scale)


def noisy_configurations(model: pin.Model, q: np.ndarray, level: float, rng: np.random.Generator) -> np.ndarray:
    """Configurations (N, nq) perturbed in the tangent space: ``q_k (+) dq_k`` with ``dq_k`` (nv,)
    of standard deviation ``level`` times each tangent coordinate's spread over the record (its
    displacement ``q_k (-) q_0``, Pinocchio's ``difference``)."""
    q = np.atleast_2d(np.asarray(q, float))
    if q.shape[1:] != (model.nq,):
        raise BadShape(f"noisy configurations: q must have shape (N, {model.nq}), got {q.shape}")
    spread = channel_scale(np.array([pin.difference(model, q[0], qk) for qk in q]), positions=True)
    steps = rng.normal(size=(len(q), model.nv)) * (level * spread)
    return np.array([pin.integrate(model, qk, dq) for qk, dq in zip(q, steps)])


def differentiate(t: np.ndarray, x: np.ndarray, window: int = 21, order: int = 3) -> np.ndarray:
    """``dx/dt`` (N, c) of a record x (N, c) sampled at evenly spaced times t (N,), by a
    Savitzky-Golay filter of ``window`` samples (odd) and polynomial ``order`` (module docstring).

    Raises:
        InvalidArgument: for uneven sampling, an even window, an order not below the window, or
            a record shorter than the window.
        BadShape: for x with another number of samples than t.
    """
    t, x = np.asarray(t, float), np.asarray(x, float)
    if x.shape[:1] != t.shape:
        raise BadShape(f"differentiate: x has {x.shape[0]} samples, t has {len(t)}")
    steps = np.diff(t)
    if len(t) < window or window % 2 == 0 or not 0 <= order < window:
        raise InvalidArgument(f"differentiate: window must be odd, at most the {len(t)} samples and above the order "
                              f"{order}; got {window}")
    if np.ptp(steps) > 1e-9 * steps.mean():
        raise InvalidArgument("differentiate: the samples must be evenly spaced in time")
    return scipy.signal.savgol_filter(x, window, order, deriv=1, delta=float(steps.mean()), axis=0)


def _centres(samples: int, window: int, order: int) -> np.ndarray:
    """Indices of the centre samples, ``window // 2`` apart from the ends and ``window`` apart.

    Raises:
        InvalidArgument: for an even window, an order not below it, or fewer samples.
    """
    if window % 2 == 0 or not 0 <= order < window or samples < window:
        raise InvalidArgument(f"smooth: window must be odd, at most the {samples} samples and above the order "
                              f"{order}; got {window}")
    return np.arange(window // 2, samples - window // 2, window)


def smooth(x: np.ndarray, window: int = 101, order: int = 3) -> tuple[np.ndarray, np.ndarray]:
    """``(indices, smoothed)``: the local polynomial fit of ``order`` over ``window`` samples (odd)
    at every ``window``-th sample of a record x (N, c) (module docstring): indices (M,), values
    (M, c)."""
    x = np.asarray(x, float)
    centres = _centres(len(x), window, order)
    weights = scipy.signal.savgol_coeffs(window, order, use="dot")
    half = window // 2
    return centres, np.array([weights @ x[k - half: k + half + 1] for k in centres])


def smooth_configurations(model: pin.Model, q: np.ndarray, window: int = 101,
                          order: int = 3) -> tuple[np.ndarray, np.ndarray]:
    """:func:`smooth` for configurations q (N, nq): at each centre sample ``q_k``, the fit of the
    window's displacements ``q_k (-) q_j`` (Pinocchio's ``difference``, (nv,) each) mapped back by
    ``q_k (+) fit``, so a base quaternion stays a unit quaternion for any attitude."""
    q = np.atleast_2d(np.asarray(q, float))
    centres = _centres(len(q), window, order)
    weights = scipy.signal.savgol_coeffs(window, order, use="dot")
    half = window // 2
    out = []
    for k in centres:
        steps = np.array([pin.difference(model, q[k], qj) for qj in q[k - half: k + half + 1]])
        out.append(pin.integrate(model, q[k], weights @ steps))
    return centres, np.array(out)


def filtered_record(model: pin.Model, t: np.ndarray, q: np.ndarray, v: np.ndarray, tau: np.ndarray,
                    window: int = 101, order: int = 3) -> tuple[np.ndarray, ...]:
    """A measured record (N samples: t (N,), q (N, nq), v and tau (N, nv)) filtered and decimated
    alike (Gautier's parallel filtering): q, v and tau smoothed (:func:`smooth`,
    :func:`smooth_configurations`) and the accelerations differentiated from v
    (:func:`differentiate`), all at every ``window``-th sample, so the samples' noises stay
    independent. Returns ``(t, q, v, a, tau)`` at those samples."""
    index, q_s = smooth_configurations(model, q, window, order)
    a = differentiate(t, v, window, order)[index]
    return np.asarray(t)[index], q_s, smooth(v, window, order)[1], a, smooth(tau, window, order)[1]
