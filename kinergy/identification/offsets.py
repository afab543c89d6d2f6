"""Which torque sensor offsets the logs determine (the full method against measured torques).

A sensor offset is a constant on its joint's torque (:func:`kinergy.predict.sensor_torque`). Some
motions cannot tell it from the other parameters: on a joint whose load never changes sign, a
friction whose Coulomb level depends on the direction of power flow (``power_flow``) adds
``coulomb_direct - coulomb_reverse`` times the load's sign while the joint moves, which is a
constant too; and a joint that swings little about one pose has gravity torques close to a
constant. Its least-squares value then follows the noise, and what it absorbs is lost for the
parameters it trades with.

The regression's standard errors assume independent residuals; those of a real log sampled at
1 kHz are correlated over tens of samples, so they understate the error. With ``rho_j`` the
lag-one autocorrelation of joint ``j``'s residuals (an AR(1) model), the effective number of
samples is ``N (1 - rho_j) / (1 + rho_j)``, so the offset's standard error is::

    sigma_eff = sigma * sqrt((1 + rho_j) / (1 - rho_j))

An offset below :data:`SIGNIFICANCE` times ``sigma_eff`` is not determined: it keeps the model's
value (its column fixed, :attr:`~kinergy.identification.columns.Columns.fixed`) and the fit is
made again without it.
"""

from __future__ import annotations

import dataclasses

import numpy as np
from numpy.typing import NDArray

from kinergy.identification.chunks import LogChunks
from kinergy.identification.columns import Columns, Regression
from kinergy.identification.regression import FlowFit, Solved

__all__ = [
    "MAX_RHO",
    "SIGNIFICANCE",
    "fixed_notes",
    "residual_correlation",
    "weak_offsets",
    "with_fixed",
]

#: an offset is determined when it is at least this many effective standard errors from zero
SIGNIFICANCE = 2.0
#: the largest lag-one autocorrelation used (a residual that is all drift would divide by zero)
MAX_RHO = 0.999


def residual_correlation(
    reg: Regression, logs: LogChunks, flow: FlowFit, solved: Solved
) -> NDArray:
    """Each joint's lag-one autocorrelation of the residuals ``y - A x`` of the fit ``solved``,
    over every piece of rows (pairs within a piece), shape (n,), in [0, :data:`MAX_RHO`]."""
    n = reg.robot.n
    lagged, total = np.zeros(n), np.zeros(n)
    loads = iter(flow.loads) if flow.loads is not None else None
    for _, rows in reg.rows(logs, loads):
        r = rows.y3 - rows.a @ solved.x
        lagged += np.sum(r[1:] * r[:-1], axis=0)
        total += np.sum(r * r, axis=0)
    with np.errstate(divide="ignore", invalid="ignore"):
        rho = np.where(total > 0.0, lagged / total, 0.0)
    return np.asarray(np.clip(rho, 0.0, MAX_RHO), dtype=float)


def weak_offsets(
    reg: Regression, logs: LogChunks, flow: FlowFit, solved: Solved
) -> NDArray[np.intp]:
    """The offset columns (indices into all) whose value is below :data:`SIGNIFICANCE` effective
    standard errors (module docstring), or that the regression dropped; empty without offsets."""
    cols = reg.cols
    if cols.offset_at is None:
        return np.zeros(0, dtype=np.intp)
    at = cols.offset_at + np.arange(reg.robot.n)
    rho = residual_correlation(reg, logs, flow, solved)
    sigma = solved.std[at] * np.sqrt((1.0 + rho) / (1.0 - rho))
    value = solved.x[at]
    weak = ~(np.abs(value) >= SIGNIFICANCE * sigma)  # NaN (dropped) counts as weak
    return np.asarray(at[weak], dtype=np.intp)


def with_fixed(reg: Regression, weak: NDArray[np.intp]) -> Regression:
    """``reg`` with the ``weak`` offset columns fixed at the model's values."""
    fixed = np.union1d(reg.cols.fixed, weak).astype(np.intp)
    return dataclasses.replace(reg, cols=dataclasses.replace(reg.cols, fixed=fixed))


def fixed_notes(cols: Columns) -> list[str]:
    """A note for the rotor inertias and the offsets kept from the model (:attr:`Columns.fixed`)."""
    out = []
    for group, what, why in (
        (
            "rotor",
            "rotor inertias",
            "their torque sensors sit on the link side, where the rotors' inertia torque does "
            "not reach (robot file: torque_sensor.side)",
        ),
        (
            "offset",
            "torque sensor offsets",
            "the logs do not tell them from the other parameters (below "
            f"{SIGNIFICANCE:g} standard errors, corrected for the residuals' correlation)",
        ),
    ):
        joints = [cols.joint_of(int(k)) + 1 for k in cols.fixed if cols.group[k] == group]
        if joints:
            listed = ", ".join(map(str, joints))
            out.append(f"{what} of joint(s) {listed} kept from the model: {why}")
    return out
