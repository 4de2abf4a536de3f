"""Least squares with the noise's covariance estimated from the residuals, and confidence
intervals.

The data are ``y = W theta + e`` stacked in blocks of ``b`` rows, one block per sample (a sample's
joint torques, or its six momentum components). Assumptions, stated once: the blocks' errors are
independent, zero-mean and share one covariance ``Sigma`` (b, b) (white, stationary sensor noise;
noise in the measured q and v enters through ``W`` and, to first order, adds to ``e``, whose
second-order bias is neglected); ``W`` has full column rank (use base parameters,
:mod:`~.base`). Then, iterated feasible generalised least squares:

1. ordinary least squares, ``theta_0``, residual blocks ``r_k`` (b,); ``Sigma = sum_k r_k r_k^T /
   (N - n / b)`` (``weighting="block"``), only its diagonal (``"diagonal"``: a sigma per row of
   the block, e.g. per joint, as Gautier weights), or one sigma for all rows (``"none"``);
2. each block whitened by ``L^-1`` (``Sigma = L L^T``): ``theta^ = argmin |L^-1 (y - W theta)|^2``;
3. ``Sigma`` again from the new residuals, and 2-3 repeated until it settles (the new ``Sigma``
   whitened by the previous ``L`` within 1e-6 of the identity; at most :data:`MAX_PASSES`
   passes; the iteration converges to the Gaussian maximum-likelihood estimate). One pass is not
   enough: the first estimate's error, driven by the noisiest rows, leaks into the quiet rows'
   residuals and overstates their noise (tenfold and more for a wrist joint next to the
   shoulder's torques). Exact data (residuals at round-off, :data:`ROUND_OFF`) stay unweighted;

with the covariance of the least-squares estimate

.. math:: \\mathrm{cov}(\\hat\\theta) = \\hat\\sigma^2 (\\tilde W^T \\tilde W)^{-1}, \\quad
          \\hat\\sigma^2 = \\frac{|\\tilde y - \\tilde W \\hat\\theta|^2}{N b - n}

(``sigma^2`` near 1 after whitening). Intervals use Student's t with ``N b - n`` degrees of
freedom; the joint box (:meth:`Estimate.half_width` with ``joint``) encloses the confidence ellipsoid
``(theta - theta^)^T cov^-1 (theta - theta^) <= n F(level; n, N b - n)`` (Scheffé), so the whole
vector lies in it with the stated probability.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.stats

from ...errors import BadShape, InvalidArgument, UnknownName
from ..threads import single_blas_thread

#: How the residuals weight the next pass (module docstring).
WEIGHTINGS = ("block", "diagonal", "none")
#: Most passes of weighting and refitting; they stop earlier once Sigma moves by under 1e-6.
MAX_PASSES = 50
#: Residuals below this fraction of the data (RMS) are round-off: exact data, no weighting.
ROUND_OFF = 1e-12


@dataclass(frozen=True)
class Estimate:
    """A least-squares estimate and its uncertainty.

    Attributes:
        values: theta^ (n,).
        covariance: its covariance (n, n).
        noise: the residual covariance per block, ``Sigma`` (b, b), in the data's units.
        dof: degrees of freedom ``N b - n``.
        condition: condition number of the whitened regressor (its columns scaled to unit norm).
        names: what each value is (n,).
    """

    values: np.ndarray
    covariance: np.ndarray
    noise: np.ndarray
    dof: int
    condition: float
    names: tuple[str, ...]

    @property
    def std(self) -> np.ndarray:
        """Standard deviations (n,)."""
        return np.sqrt(np.diag(self.covariance))

    def interval(self, level: float = 0.95) -> tuple[np.ndarray, np.ndarray]:
        """``(lower, upper)`` (n,) each: two-sided intervals holding each value with probability
        ``level`` (Student's t, :attr:`dof`)."""
        half = self.half_width(level)
        return self.values - half, self.values + half

    def half_width(self, level: float = 0.95, joint: bool = False) -> np.ndarray:
        """Half-widths (n,): of each value's ``level`` interval, or with ``joint`` of the box
        enclosing the joint confidence ellipsoid (module docstring).

        Raises:
            InvalidArgument: for a level outside (0, 1).
        """
        if not 0.0 < level < 1.0:
            raise InvalidArgument(f"confidence level must be in (0, 1), got {level}")
        if joint:
            n = len(self.values)
            return np.sqrt(n * scipy.stats.f.ppf(level, n, self.dof)) * self.std
        return scipy.stats.t.ppf(0.5 + 0.5 * level, self.dof) * self.std


@single_blas_thread
def fit(W: np.ndarray, y: np.ndarray, block: int, names: tuple[str, ...] | None = None,
        weighting: str = "block") -> Estimate:
    """The estimate of ``y = W theta + e`` (module docstring).

    Args:
        W: regressor (N b, n), sample-major.
        y: measurements (N b,).
        block: rows per sample, b.
        names: of the parameters (n,); default ``theta0``, ``theta1``, ...
        weighting: ``"block"``, ``"diagonal"`` or ``"none"`` (:data:`WEIGHTINGS`).

    Raises:
        BadShape: for mismatched shapes, rows not a whole number of blocks, or no more rows than
            parameters.
        InvalidArgument: for a rank-deficient regressor (naming the best-determined null
            direction's largest parameters) or a zero residual in a row the weighting divides by.
        UnknownName: for an unknown weighting.
    """
    W, y = np.asarray(W, float), np.asarray(y, float)
    rows, n = W.shape
    names = tuple(names) if names is not None else tuple(f"theta{i}" for i in range(n))
    if weighting not in WEIGHTINGS:
        raise UnknownName("weighting", weighting, WEIGHTINGS)
    if y.shape != (rows,) or len(names) != n:
        raise BadShape(f"least squares: W {W.shape}, y {y.shape} and {len(names)} names do not agree")
    if block < 1 or rows % block:
        raise BadShape(f"least squares: {rows} rows are not a whole number of blocks of {block}")
    if rows <= n:
        raise BadShape(f"least squares: {rows} rows cannot estimate {n} parameters with a residual; add samples")
    _check_rank(W, names)
    values = np.linalg.lstsq(W, y, rcond=None)[0]
    Wt, yt, whiten = W, y, None
    for _ in range(MAX_PASSES):
        residual = (y - W @ values).reshape(-1, block)
        sigma = _noise_covariance(residual, n, weighting)
        if np.sqrt(np.mean(residual**2)) <= ROUND_OFF * np.sqrt(np.mean(y**2)):
            break  # exact data: weights would fit round-off, the estimate stays unweighted
        settled = whiten is not None and np.abs(whiten @ sigma @ whiten.T - np.eye(block)).max() < 1e-6
        whiten = _whitening(sigma)
        Wt = np.einsum("ij,kjn->kin", whiten, W.reshape(-1, block, n)).reshape(rows, n)
        yt = (y.reshape(-1, block) @ whiten.T).ravel()
        values = np.linalg.lstsq(Wt, yt, rcond=None)[0]
        if settled:
            break
    dof = rows - n
    s2 = float(np.sum((yt - Wt @ values) ** 2)) / dof
    R = np.linalg.qr(Wt, mode="r")
    R_inv = np.linalg.inv(R)
    scaled = Wt / np.linalg.norm(Wt, axis=0)
    singular = np.linalg.svd(scaled, compute_uv=False)
    return Estimate(values, s2 * R_inv @ R_inv.T, sigma, dof, float(singular[0] / singular[-1]), names)


def _noise_covariance(residual: np.ndarray, n: int, weighting: str) -> np.ndarray:
    """``Sigma`` (b, b) of residual blocks (N, b) left by n parameters, as ``weighting`` says."""
    block = residual.shape[1]
    sigma = residual.T @ residual / (len(residual) - n / block)
    if weighting == "diagonal":
        return np.diag(np.diag(sigma))
    if weighting == "none":
        return np.eye(block) * np.trace(sigma) / block
    return sigma


def _whitening(sigma: np.ndarray) -> np.ndarray:
    """``L^-1`` with ``Sigma = L L^T`` (b, b).

    Raises:
        InvalidArgument: for a singular Sigma (a row the model fits exactly).
    """
    try:
        return np.linalg.inv(np.linalg.cholesky(sigma))
    except np.linalg.LinAlgError:
        raise InvalidArgument(f"least squares: the residual covariance per block is singular (diagonal "
                              f"{np.diag(sigma).tolist()}): a row fits exactly; drop it or use weighting='none'") from None


def _check_rank(W: np.ndarray, names: tuple[str, ...]) -> None:
    """Raises InvalidArgument when ``W``'s columns (scaled to unit norm) are dependent to 1e-10."""
    norms = np.linalg.norm(W, axis=0)
    zero = [names[i] for i in np.flatnonzero(norms == 0.0)]
    if zero:
        raise InvalidArgument(f"least squares: the data never excite {', '.join(zero[:5])}: a zero regressor column "
                              "(identify base parameters instead)")
    _, s, Vt = np.linalg.svd(W / norms, full_matrices=False)
    if s[-1] <= 1e-10 * s[0]:
        worst = np.argsort(-np.abs(Vt[-1]))[:3]
        raise InvalidArgument(f"least squares: the regressor is rank-deficient (condition {s[0] / max(s[-1], 1e-300):.3g}); "
                              f"{', '.join(names[i] for i in worst)} cannot be told apart: identify base parameters "
                              "or excite more")
