"""The identified parameters' errors, from a delete-one-block jackknife over time.

Least-squares standard errors assume independent residuals; a robot's are not (coloured noise,
friction and model error that follow the motion), and they come out over-confident. The
jackknife does not assume it: the samples are cut into ``K`` contiguous time blocks (many
times longer than the residuals' correlation), the regression is solved ``K`` times, each
without one block, and the spread of those solutions is the estimator's (Efron & Stein; for
dependent data Kunsch, "The jackknife and the bootstrap for general stationary observations",
Annals of Statistics 1989)::

    theta_(k) = argmin sum_{b != k} |y_b - A_b theta|^2,   k = 1..K
    Sigma_J   = (K - 1) / K  sum_k (theta_(k) - theta_bar)(theta_(k) - theta_bar)^T

It costs no second read of the logs: each step already folds its rows into a QR triangle per
block (:mod:`kinergy.identification.drive_steps`), and a replicate's problem is the other blocks'
triangles stacked (``R_(k) = qr([R_b for b != k])``). Step 2 (rotor inertias) and step 3
(torque constant and friction of each motor, eq 18) are each jackknifed over the same ``K``
blocks of the stacked samples (:data:`~kinergy.identification.drive_steps.JACKKNIFE_BLOCKS`;
with ``--friction auto`` its cross-validation's blocks), so replicate ``k`` of every parameter
leaves out the same stretch of time and the covariance across joints and steps comes with it.
The rotor inertias of a replicate are not carried into its current fit (a second-order effect on
the current's load torque). A parameter the logs did not identify (kept from the model) carries
no error. The result is the robot file's ``[uncertainty]``
(:class:`~kinergy.model.uncertainty.Uncertainty`): the rows ``D_k = sqrt((K-1)/K) (theta_(k) -
theta_bar)``, and ``K - 1`` degrees of freedom for the t quantile of every interval.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np

from kinergy.arrays import Array
from kinergy.identification.drive_steps import (
    JACKKNIFE_BLOCKS,
    CurrentStats,
    grouped,
    joined,
    rotor_solution,
)
from kinergy.identification.electrics import BLOCK_SECONDS, StandingDrawSums
from kinergy.identification.result import IDENTIFIED, Validation
from kinergy.linalg import Reduced
from kinergy.model.robot import Robot, transmission_matrix
from kinergy.model.uncertainty import Uncertainty
from kinergy.predict import DriveState

__all__ = [
    "current_shifts",
    "deviations",
    "fit_residual",
    "fold_gradients",
    "jackknife_uncertainty",
    "supply_calibration",
    "torque_shifts",
    "with_standing_draw",
]


def deviations(replicates: Array) -> Array:
    """The jackknife's error modes (K, p) of its ``replicates`` (K, p): ``sqrt((K-1)/K)
    (theta_(k) - theta_bar)``, so that ``modes.T @ modes`` is its covariance."""
    k = replicates.shape[0]
    return np.sqrt((k - 1) / k) * (replicates - replicates.mean(axis=0))


def _rotor_replicates(
    robot: Robot, pieces: Sequence[Reduced], active: Sequence[int], blocks: int
) -> Array | None:
    """Step 2 without each of ``blocks`` groups of ``pieces``: (K, len(active)), kg m^2."""
    groups = grouped(pieces, blocks)
    if len(groups) < 3:
        return None
    rows = []
    for k in range(len(groups)):
        inertia, _, _ = rotor_solution(robot, joined(groups[:k] + groups[k + 1 :]), active)
        rows.append(inertia[list(active)])
    return np.array(rows)


def jackknife_uncertainty(
    identified: Robot,
    rotor_pieces: Sequence[Reduced] | None,
    flags: Sequence[Mapping[str, str]],
    stats: Sequence[CurrentStats],
) -> Uncertainty | None:
    """The identified parameters' errors (module docstring) from step 2's triangles
    ``rotor_pieces`` and each joint's step-3 replicates (``stats[j].replicates``), for the
    parameters whose ``flags`` say ``identified``; None when there are none (or too few blocks).
    """
    names: list[str] = []
    columns: list[Array] = []
    counts = [s.replicates.shape[0] for s in stats if s.replicates is not None]
    blocks = counts[0] if counts else JACKKNIFE_BLOCKS
    rotor_joints = [j for j, f in enumerate(flags) if f.get("rotor_inertia") == IDENTIFIED]
    if rotor_pieces and rotor_joints:
        reps = _rotor_replicates(identified, rotor_pieces, rotor_joints, blocks)
        if reps is not None and (not counts or reps.shape[0] == blocks):
            for c, j in enumerate(rotor_joints):
                names.append(f"joints[{j}].rotor_inertia")
                columns.append(reps[:, c])
    for j, stat in enumerate(stats):
        if stat.replicates is None:
            continue
        model = identified.joints[j].drive.friction.model
        if flags[j].get("torque_constant") == IDENTIFIED:
            names.append(f"joints[{j}].torque_constant")
            columns.append(stat.replicates[:, 0])
        for c, name in enumerate(model.linear):
            if flags[j].get(name) == IDENTIFIED:
                names.append(f"joints[{j}].friction.{name}")
                columns.append(stat.replicates[:, 1 + c])
    sizes = {c.size for c in columns}
    if not columns or len(sizes) != 1:
        return None
    replicates = np.column_stack(columns)
    k = replicates.shape[0]
    return Uncertainty(
        parameters=tuple(names),
        modes=deviations(replicates),
        dof=k - 1,
        method=f"jackknife over {k} time blocks",
    )


def fold_gradients(
    gradients: dict[tuple[int, int], Array],
    sums: StandingDrawSums,
    segment: int,
    t: Array,
    columns: Array,
) -> None:
    """Add the motors' supply-energy gradient of samples at times ``t`` (s, (N,)) of log
    ``segment``, ``columns`` (N, p) W per parameter unit, into ``gradients`` per block of
    ``sums`` (the standing draw's :data:`~kinergy.identification.electrics.BLOCK_SECONDS`
    blocks), J per parameter unit."""
    if t.size == 0:
        return
    start = sums.origin.get(segment, float(t[0]))
    dt = np.gradient(t) if t.size > 1 else np.zeros(1)
    index = np.floor((t - start) / BLOCK_SECONDS).astype(int)
    for b in np.unique(index):
        inside = index == b
        add = dt[inside] @ columns[inside]
        key = (segment, int(b))
        gradients[key] = gradients.get(key, 0.0) + add


def supply_calibration(
    uncertainty: Uncertainty,
    sums: StandingDrawSums,
    gradients: dict[tuple[int, int], Array],
    standby: float,
) -> tuple[float, int]:
    """The factor ``c >= 1`` by which the parameter errors understate the model's error on the
    logged supply, and the blocks ``B`` it was measured on: over the standing draw's blocks
    ``b`` of the identification logs, the supply energy the model misses (``e_b``: the block's
    supply less the motors' predicted draw less the standing draw, J) against the spread the
    parameter errors give it (``s_b = |D g_b|``, ``g_b`` the block's gradient)::

        c^2 = max(1, sum_b e_b^2 / sum_b s_b^2)

    It takes in what the parameters cannot: a friction shape or electrics the model lacks (the
    supply's own noise too, but on the twin and on UR logs that is a few mJ a block). A
    block's ``e_b`` takes its log's sample period (the full blocks' ``BLOCK_SECONDS / n_b``), so
    that a log's last, shorter block counts its own seconds."""
    period: dict[int, float] = {}
    for (segment, _), (_, count) in sums.blocks.items():
        period[segment] = min(period.get(segment, np.inf), BLOCK_SECONDS / max(count, 1.0))
    errors, spreads = [], []
    for key, (total, count) in sums.blocks.items():
        if key not in gradients or count < 2:
            continue
        errors.append((total - count * standby) * period[key[0]])
        spreads.append(uncertainty.spread(gradients[key]))
    if not errors:
        return 1.0, 0
    ratio = float(np.sum(np.square(errors)) / max(np.sum(np.square(spreads)), 1e-300))
    return float(np.sqrt(max(ratio, 1.0))), len(errors)


def with_standing_draw(
    uncertainty: Uncertainty | None,
    std: float,
    calibration: tuple[float, int] | None = None,
) -> Uncertainty:
    """``uncertainty`` with the arm's standing draw, its standard error ``std`` (W) independent
    of the drives' errors: one more mode, nonzero in ``standby_power`` alone; and the
    ``calibration`` :func:`supply_calibration` found (None: not calibrated).

    A factor ``c > 1`` sets the variance's scale (``c^2 |D g|^2 = sum_b e_b^2 |D g|^2 / sum_b
    |D g_b|^2``: the modes' own scale cancels), so the interval's t quantile then takes the
    degrees of freedom of that estimate, ``B - 1`` (``B`` blocks' misses, less the standing draw
    fitted from them: batch means), not the jackknife's ``K - 1``."""
    if uncertainty is None:
        return Uncertainty(("standby_power",), np.array([[std]]), 30, "standing-draw batch means")
    k = uncertainty.modes.shape[0]
    modes = np.zeros((k + 1, len(uncertainty.parameters) + 1))
    modes[:k, :-1] = uncertainty.modes
    modes[k, -1] = std
    method = uncertainty.method + "; standing draw from its batch means"
    factor, dof = uncertainty.calibration, uncertainty.dof
    if calibration is not None:
        factor, blocks = calibration
        method += f"; x {factor:.3g} calibrated on the logged supply's {BLOCK_SECONDS:g} s blocks"
        if factor > 1.0 and blocks > 2:
            dof = blocks - 1
            method += f" (t on their {dof} degrees of freedom)"
    parameters = (*uncertainty.parameters, "standby_power")
    return Uncertainty(parameters, modes, dof, method, factor, uncertainty.residual)


def fit_residual(fit: Validation) -> dict[str, tuple[float, ...]]:
    """Per joint, the RMS error of the identified model's ``current`` and reference ``torque``
    on its identification logs (``fit``: its :class:`~kinergy.identification.result.Validation`
    there; NaN for a joint not compared), for :attr:`Uncertainty.residual`."""
    out = {}
    for key in ("current", "torque"):
        metrics = getattr(fit, key)
        if metrics is not None:
            out[key] = tuple(float("nan") if m is None else float(m.rms) for m in metrics)
    return out


def _joint_parameters(u: Uncertainty) -> dict[int, list[tuple[int, str]]]:
    """Per joint, its parameters in ``u``: (column of ``u.modes``, ``rotor_inertia``,
    ``torque_constant`` or the friction level's name)."""
    out: dict[int, list[tuple[int, str]]] = {}
    for i, name in enumerate(u.parameters):
        if name.startswith("joints["):
            j = int(name[7 : name.index("]")])
            out.setdefault(j, []).append((i, name.split(".", 1)[1].removeprefix("friction.")))
    return out


def current_shifts(robot: Robot, state: DriveState, temperature: Array | None = None) -> Array:
    """How each error mode of ``robot.uncertainty`` moves the currents it predicts on the motion
    of ``state`` (UR5e eq 17, ``I = tau_m / k_t``; the calibration factor ``c`` included),
    (K, N, n) A: ``c sum_i D_ki dI_j/dtheta_i`` over joint j's parameters, with::

        dI/dJ_r = dwm / k_t,   dI/dk_t = -tau_m / k_t^2,   dI/df = column_f / k_t

    (a rotor inertia moves the load torque by ``dJ dwm``; a friction level ``f`` by its
    regressor column, the friction taken at the nominal load). The standard deviation of the
    predicted current is ``sqrt(sum_k shifts_k^2)`` (``|D g|`` sample by sample)."""
    u = robot.uncertainty
    assert u is not None
    shifts = np.zeros((u.modes.shape[0], *state.current.shape))
    for j, params in _joint_parameters(u).items():
        drive = robot.joints[j].drive
        kt = drive.torque_constant
        columns = None
        for i, what in params:
            if what == "rotor_inertia":
                g = state.dwm[:, j] / kt
            elif what == "torque_constant":
                g = -state.tau_m[:, j] / kt**2
            else:
                if columns is None:
                    temp = None if temperature is None else temperature[:, j]
                    columns = drive.friction.model.friction_columns(
                        drive.friction.params,
                        state.wm[:, j],
                        state.tau_load[:, j],
                        state.dwm[:, j],
                        temperature=temp,
                    )
                g = columns[:, drive.friction.model.linear.index(what)] / kt
            shifts[:, :, j] += np.outer(u.modes[:, i], g)
    return u.calibration * shifts


def torque_shifts(robot: Robot, dwm: Array) -> Array:
    """How each error mode of ``robot.uncertainty`` moves the reference torque it predicts
    (``target_moment``, UR5e eq 7: ``tau_sim = f_link + N^T diag(J) N qdd``) for motor
    accelerations ``dwm`` (N, n), (K, N, n) N m: ``c sum_j D_kj dwm_j N[j, :]`` over the rotor
    inertias ``J_j`` (the one parameter of ``robot.uncertainty`` in eq 7)."""
    u = robot.uncertainty
    assert u is not None
    n_mat = transmission_matrix(robot)
    moved = np.zeros((u.modes.shape[0], dwm.shape[1]))  # dJ per mode and motor
    for j, params in _joint_parameters(u).items():
        for i, what in params:
            if what == "rotor_inertia":
                moved[:, j] = u.modes[:, i]
    return u.calibration * np.einsum("kj,nj,ji->kni", moved, dwm, n_mat)
