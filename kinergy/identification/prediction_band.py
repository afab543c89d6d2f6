"""``validate``'s 95 % prediction band: where a measured current or reference torque should fall.

A model that carries its parameters' errors (:class:`~kinergy.model.uncertainty.Uncertainty`,
error modes ``D``, K x p, and the calibration factor ``c``) predicts each sample's current (and
``target_moment``) with a spread, sample by sample (``s_n = c |D g_n|``, ``g_n`` the sample's
gradient over the parameters: :func:`~kinergy.identification.uncertainty.current_shifts`,
:func:`~kinergy.identification.uncertainty.torque_shifts`). A measured sample also carries what
the model misses whatever its parameters (noise, friction it does not have): the RMS error
``r_j`` of joint j on the identification logs (``[uncertainty] residual``). The band is a
*prediction* interval on the measured sample, each part at its own quantile::

    half_n = sqrt((t_{0.975, nu} s_n)^2 + (z_{0.975} r_j)^2)

(``nu`` the modes' degrees of freedom; ``r_j`` comes from hundreds of thousands of samples, so
the normal quantile). Without the residual (a model identified before it was kept) the band is
the parameters' alone and says so. The held-out metrics' spread across the modes: each metric
recomputed with the predictions moved by each mode (``m_k = m(pred + c D_k g)``, to first
order), ``std m = sqrt(sum_k (m_k - m)^2)`` (the jackknife's spread, as the modes are
``sqrt((K-1)/K)`` times the replicates' deviations).

Everything is folded chunk by chunk (:class:`BandTally`): memory bounded by the chunk.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from kinergy.arrays import Array
from kinergy.model.uncertainty import LEVEL, Uncertainty, t_quantile

__all__ = ["NO_BAND", "BandTally", "PredictionBand", "SignalBand", "half_widths"]

#: what ``validate`` says instead of a band when the model carries no errors
NO_BAND = (
    "the model carries no parameter errors (a built-in or data-sheet model): no interval; "
    "identify a model from logs for one"
)
#: the normal quantile of the residual's part of the band
_Z = 1.959963984540054


@dataclass(frozen=True)
class SignalBand:
    """One signal's 95 % prediction band over ``samples`` samples, per joint: the share of the
    measured samples inside it (``inside``, 0-1), its mean half-width (``half_width``, the
    signal's units), the RMS error (measured - predicted) with its spread across the error
    modes (``rms``, ``rms_std``) and R^2's spread (``r2_std``)."""

    samples: int
    inside: tuple[float, ...]
    half_width: tuple[float, ...]
    rms: tuple[float, ...]
    rms_std: tuple[float, ...]
    r2_std: tuple[float, ...]


@dataclass(frozen=True)
class PredictionBand:
    """``validate``'s prediction band (module docstring): its ``level`` and ``method``, and per
    signal its :class:`SignalBand` (None where not compared); or, for a model without errors,
    ``note`` (:data:`NO_BAND`) and nothing else."""

    level: float = LEVEL
    method: str | None = None
    current: SignalBand | None = None
    torque: SignalBand | None = None
    note: str | None = None


def band_method(u: Uncertainty) -> str:
    """How the band of a model with errors ``u`` is made, for the user."""
    noise = (
        "plus the identification logs' RMS error of each joint (normal quantile): a prediction "
        "interval on the measured samples"
        if u.residual
        else "the parameters' errors alone (the model keeps no identification residual)"
    )
    return (
        f"t quantile ({u.dof} degrees of freedom) x the spread of each sample's prediction over "
        f"the model's parameter errors ({u.method}), {noise}"
    )


def half_widths(u: Uncertainty, shifts: Array, signal: str) -> Array:
    """The band's half-width (N, n) for the modes' ``shifts`` (K, N, n) of a ``signal``'s
    prediction (``current`` or ``torque``; module docstring)."""
    half = t_quantile(u.dof) * np.sqrt(np.sum(np.square(shifts), axis=0))
    residual = u.residual.get(signal)
    if residual is None:
        return half
    noise = _Z * np.nan_to_num(np.asarray(residual, dtype=float))
    return np.sqrt(half**2 + noise**2)


class BandTally:
    """A signal's :class:`SignalBand` folded chunk by chunk (one per log; :meth:`merge`)."""

    def __init__(self, modes: int, n: int):
        self.count = 0
        self.inside = np.zeros(n)
        self.half = np.zeros(n)
        self.err_sq = np.zeros(n)
        self.cross = np.zeros((modes, n))  # sum of err * shift_k
        self.shift_sq = np.zeros((modes, n))
        self.sum = np.zeros(n)
        self.sq = np.zeros(n)

    def add(self, measured: Array, predicted: Array, shifts: Array, half: Array) -> None:
        """Fold in (N, n) measured and predicted samples, the modes' shifts of the prediction
        (K, N, n) and the band's half-widths (N, n)."""
        err = measured - predicted
        self.count += err.shape[0]
        self.inside += np.sum(np.abs(err) <= half, axis=0)
        self.half += half.sum(axis=0)
        self.err_sq += np.sum(err**2, axis=0)
        self.cross += np.einsum("nj,knj->kj", err, shifts)
        self.shift_sq += np.sum(shifts**2, axis=1)
        self.sum += measured.sum(axis=0)
        self.sq += np.sum(measured**2, axis=0)

    def merge(self, other: BandTally) -> None:
        for name, value in vars(other).items():
            setattr(self, name, getattr(self, name) + value)

    def result(self) -> SignalBand | None:
        if self.count == 0:
            return None
        n = self.count
        sse_k = self.err_sq - 2.0 * self.cross + self.shift_sq  # the error moved by each mode
        rms = np.sqrt(self.err_sq / n)
        rms_std = np.sqrt(np.sum((np.sqrt(np.maximum(sse_k, 0.0) / n) - rms) ** 2, axis=0))
        sst = self.sq - self.sum**2 / n
        with np.errstate(divide="ignore", invalid="ignore"):
            r2_std = np.where(
                sst > 0, np.sqrt(np.sum((sse_k - self.err_sq) ** 2, axis=0)) / sst, np.nan
            )

        def listed(x: Array) -> tuple[float, ...]:
            return tuple(float(v) for v in x)

        return SignalBand(
            n,
            listed(self.inside / n),
            listed(self.half / n),
            listed(rms),
            listed(rms_std),
            listed(r2_std),
        )
