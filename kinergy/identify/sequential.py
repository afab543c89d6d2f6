"""The UR5e doc's sequential identification (sections 3-4).

1. Link data are taken from the robot model (UR's published masses and centres of mass; the
   inertia tensors barely matter behind a 100:1 gear, UR5e section 3.1).
2. Rotor inertia ``J_m + J_r`` of every drive from the controller's reference torque: the part of
   ``target_moment`` the links do not explain is the reflected rotor inertia times the
   acceleration (eqs 7-9), solved by least squares. (For coupled joints the reflection goes
   through the coupling matrix; the same least squares holds.)
3. Torque constant and friction of every motor together from the measured current (eqs 17-18):
   the current is linear in ``1/k_t`` (times the load torque from step 2's model) and in the
   friction parameters over ``k_t``. Any friction model linear in its parameters can be used
   (the model's ``linear`` parameters, :mod:`kinergy.friction`); the UR5e doc's is ``power_flow``.
4. Motor inertia = rotor inertia - the model's reducer inertia (Table IV).

Real controllers add one thing the seed does not model: a joint that stops stays in stiction,
and its current keeps part of the friction of the direction it stopped in. With ``hold="auto"``
each joint's fit is made holding 0, 25, 50, 75 and 100 % of its friction through standstill (the
``standstill`` and ``holding`` friction parameters) and keeps the best.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

from kinergy.drives.transmission import transmission_matrix
from kinergy.dynamics.rnea import rnea
from kinergy.errors import KinergyError
from kinergy.friction.registry import (
    friction_columns,
    get_model,
    start_parameters,
    with_linear_parameters,
)
from kinergy.identify.preprocess import IdentData
from kinergy.identify.result import (
    DriveEstimate,
    Fit,
    IdentificationResult,
    friction_entry,
    validation_metrics,
)
from kinergy.jsonable import OPTIONAL
from kinergy.linalg import scaled_lstsq
from kinergy.model.robot import Friction, Robot, Source

__all__ = ["SequentialFit", "SequentialJoint", "identify_sequential", "rotor_inertias"]

Array = NDArray[np.float64]

#: joint speed below which a joint counts as still, rad/s
STILL_SPEED = 0.005
#: a regression whose column-scaled condition number exceeds this cannot be trusted
MAX_CONDITION = 1e8
#: fractions of the friction a stopped joint is tried with (0: none, the seed's model)
HOLDINGS = (0.0, 0.25, 0.5, 0.75, 1.0)
#: a holding fraction is kept only if it cuts the squared current error by this share
MIN_GAIN = 0.005
#: relative standard deviation of 1/k_t above which the torque constant counts as unidentified
MAX_KT_SPREAD = 0.1


def _stack(datas: Sequence[IdentData], name: str) -> Array:
    return np.vstack([getattr(d, name) for d in datas])


@dataclass(frozen=True)
class SequentialJoint(DriveEstimate):
    """A joint's drive from the sequential method, with standard errors (motor side) and
    whether the logs identified it (``problem`` says why not)."""

    rotor_inertia_std: float | None = None
    torque_constant_std: float | None = field(default=None, metadata=OPTIONAL)
    friction_std: dict[str, float] | None = field(default=None, metadata=OPTIONAL)
    condition_current: float | None = field(default=None, metadata=OPTIONAL)
    identified: bool = True
    problem: str | None = field(default=None, metadata=OPTIONAL)


@dataclass(frozen=True)
class SequentialFit(Fit):
    """The sequential method's fit: the condition numbers of its regressions and the friction
    hold chosen per joint (None where not fitted)."""

    condition_rotor_inertia: float | None = field(default=None, metadata=OPTIONAL)
    friction_holding: tuple[float | None, ...] | None = field(default=None, metadata=OPTIONAL)


def rotor_inertias(
    robot: Robot, datas: Sequence[IdentData], active: Sequence[int] | None = None
) -> tuple[Array, Array, float]:
    """Step 2: ``J_m + J_r`` per motor from ``target_moment`` (UR5e eqs 7-9).

    ``tau_ref - f_link = N^T diag(J) N qdd`` with ``N`` the transmission matrix, linear in J.

    Returns
    -------
    inertia, std : ndarray, shape (n,)
        kg m^2 (motor side) and its standard deviation; motors not in ``active`` (default all)
        keep the model's value and a NaN deviation.
    condition : float
    """
    active = list(range(robot.n)) if active is None else list(active)
    q, qd, qdd = _stack(datas, "q_cmd"), _stack(datas, "qd_cmd"), _stack(datas, "qdd_cmd")
    tau_ref = _stack(datas, "tau_ref")
    f_link = rnea(robot, q, qd, qdd)
    n_mat = transmission_matrix(robot)
    motor_acc = qdd @ n_mat.T  # (N, n): N qdd
    # column m: contribution of J_m to every joint torque, n_mat[m, j] * (N qdd)_m
    cols = n_mat[None, :, :] * motor_acc[:, :, None]  # (N, m, j)
    a = np.transpose(cols, (0, 2, 1)).reshape(-1, robot.n)  # rows (sample, joint), columns m
    fixed = [m for m in range(robot.n) if m not in active]
    known = np.array([j.drive.rotor_inertia for j in robot.joints])
    y = (tau_ref - f_link).reshape(-1) - a[:, fixed] @ known[fixed]
    sol, sol_std, cond = scaled_lstsq(a[:, active], y)
    inertia, std = known.copy(), np.full(robot.n, np.nan)
    inertia[active], std[active] = sol, sol_std
    return inertia, std, cond


def _diagnose_motion(robot: Robot, datas: Sequence[IdentData]) -> dict[int, str]:
    """What the logs cannot identify, per joint (index -> reason).

    Raises
    ------
    KinergyError
        Too few samples, or no joint identifiable: one line naming every joint and why.
    """
    qd = _stack(datas, "qd")
    samples = qd.shape[0]
    if samples < 50:
        raise KinergyError(
            f"cannot identify from these logs: only {samples} samples (need at least 50)"
        )
    problems: dict[int, str] = {}
    for j, joint in enumerate(robot.joints):
        speed = np.abs(qd[:, j])
        if speed.max() < 10 * STILL_SPEED:
            problems[j] = (
                f"joint {j + 1} ({joint.name}) never moves (max |qd| {speed.max():.3g} rad/s): "
                "its rotor inertia, torque constant and friction cannot be identified"
            )
        elif (qd[:, j] > STILL_SPEED).sum() < 10 or (qd[:, j] < -STILL_SPEED).sum() < 10:
            problems[j] = (
                f"joint {j + 1} ({joint.name}) never reverses: Coulomb friction in one direction "
                "and the torque constant cannot be separated"
            )
    if len(problems) == robot.n:
        raise KinergyError("cannot identify from these logs: " + "; ".join(problems.values()))
    return problems


def _current_fit(
    model: str,
    params: dict[str, float],
    tau_load: Array,
    wm: Array,
    dwm: Array,
    current: Array,
    kt_prior: float,
) -> tuple[Array, Array, float, float, bool]:
    """Eq 18 for one motor: ``I = [tau_load, friction columns] @ [1/k_t, values/k_t]``.

    When the load torque is too small against the friction and noise to pin ``1/k_t`` down
    (relative standard deviation above :data:`MAX_KT_SPREAD`, or a non-positive estimate), ``k_t``
    is fixed at ``kt_prior`` and only the friction is fitted; the last value returned says so.
    """
    cols = friction_columns(model, params, wm, tau_load, dwm)
    a = np.column_stack([tau_load, cols])
    x, std, cond = scaled_lstsq(a, current)
    fixed = not (x[0] > 0 and std[0] < MAX_KT_SPREAD * x[0])
    if fixed:
        rest, rest_std, cond = scaled_lstsq(cols, current - tau_load / kt_prior)
        x = np.concatenate([[1.0 / kt_prior], rest])
        std = np.concatenate([[0.0], rest_std])
        a_used = a
    else:
        a_used = a
    sse = float(np.sum((current - a_used @ x) ** 2))
    return x, std, cond, sse, fixed


def identify_sequential(
    robot: Robot,
    datas: Sequence[IdentData],
    *,
    friction: str | None = None,
    hold: str | bool = "auto",
) -> IdentificationResult:
    """Identify rotor inertias, torque constants and friction with the UR5e doc's procedure.

    Parameters
    ----------
    robot : Robot
        The starting model: its link data are kept.
    datas : sequence of IdentData
        Prepared logs (:func:`kinergy.identify.preprocess.prepare`). Rotor inertias need
        ``target_moment``; torque constants and friction need ``actual_current``.
    friction : str, optional
        Friction model for every joint (default: each joint's model in ``robot``); it must be
        linear in its parameters (all of kinergy's are, given their shape parameters).
    hold : {"auto", True, False}
        Hold friction through standstill (see the module docstring); ``auto`` keeps whichever
        fits the currents better.

    Returns
    -------
    IdentificationResult

    Raises
    ------
    KinergyError
        Logs that cannot identify a parameter (a joint that never moves or never reverses, too few
        samples, a singular regression), naming the joints.
    """
    if not datas:
        raise KinergyError("no log to identify from")
    problems = _diagnose_motion(robot, datas)
    active = [j for j in range(robot.n) if j not in problems]
    warnings: list[str] = [f"{text}; kept the model's values" for text in problems.values()]
    n = robot.n
    ref_logs = [d for d in datas if d.tau_ref is not None]
    current_logs = [d for d in datas if d.current is not None]
    has_ref, has_current = bool(ref_logs), bool(current_logs)
    if not (has_ref or has_current):
        raise KinergyError(
            "identification needs target_moment (rotor inertia) or actual_current (torque "
            "constant and friction); the logs have neither"
        )
    fit: dict[str, Any] = {
        "samples": int(sum(len(d) for d in datas)),
        "logs": [d.path for d in datas],
    }
    fit["lag"] = [d.lag for d in datas]
    rotor = np.array([j.drive.rotor_inertia for j in robot.joints])
    rotor_std = np.full(n, np.nan)
    if has_ref:
        rotor, rotor_std, cond = rotor_inertias(robot, ref_logs, active)
        fit["condition_rotor_inertia"] = cond
        if cond > MAX_CONDITION:
            raise KinergyError(
                f"rotor inertia regression is singular (condition {cond:.3g}): too little acceleration"
            )
    else:
        warnings.append("the logs have no target_moment: rotor inertias kept from the model")
    for j, joint in enumerate(robot.joints):
        if rotor[j] <= 0:
            warnings.append(
                f"joint {j + 1} ({joint.name}): identified rotor inertia {rotor[j]:.3g} kg m^2 is not positive"
            )
    joints = [
        dataclasses.replace(
            joint,
            drive=dataclasses.replace(
                joint.drive,
                motor_inertia=max(float(rotor[j]) - joint.drive.reducer_inertia, 0.0),
            ),
        )
        for j, joint in enumerate(robot.joints)
    ]
    for j, joint in enumerate(robot.joints):
        if rotor[j] < joint.drive.reducer_inertia:
            warnings.append(
                f"joint {j + 1} ({joint.name}): rotor inertia {rotor[j]:.3g} is below the model's "
                f"reducer inertia {joint.drive.reducer_inertia:.3g}; motor inertia set to 0"
            )
    staged = robot.with_joints(joints)
    per_joint: list[dict[str, Any]] = []
    if has_current:
        q, qd, qdd = (
            _stack(current_logs, "q"),
            _stack(current_logs, "qd"),
            _stack(current_logs, "qdd"),
        )
        current = _stack(current_logs, "current")
        n_mat = transmission_matrix(staged)
        tau_sim = rnea(staged, q, qd, qdd) + qdd @ (n_mat.T @ (rotor[:, None] * n_mat)).T
        tau_load = np.asarray(np.linalg.solve(n_mat.T, tau_sim.T).T, dtype=float)
        wm = qd @ n_mat.T
        dwm = qdd @ n_mat.T
        ratios = np.abs(np.array([j.drive.gear_ratio for j in staged.joints]))
        holdings = HOLDINGS if hold == "auto" else ((1.0,) if hold else (0.0,))
        chosen: list[Any] = []
        for m, joint in enumerate(staged.joints):
            if m in problems:
                chosen.append(None)
                continue
            model = friction or joint.drive.friction.model
            best: tuple[float, Any] | None = None
            for holding in holdings:
                params = start_parameters(
                    model, joint.drive.friction.model, joint.drive.friction.params
                )
                params.pop("standstill", None)
                params.pop("holding", None)
                if holding > 0.0:
                    params["standstill"] = STILL_SPEED * ratios[m]
                    params["holding"] = holding
                x, std, cond, sse, fixed = _current_fit(
                    model,
                    params,
                    tau_load[:, m],
                    wm[:, m],
                    dwm[:, m],
                    current[:, m],
                    joint.drive.torque_constant,
                )
                if best is None or sse < best[0] * (1.0 - MIN_GAIN):
                    best = (sse, (model, params, x, std, cond, fixed))
            assert best is not None
            chosen.append(best[1])
        fit["friction_holding"] = [
            None if c is None else float(c[1].get("holding", 0.0)) for c in chosen
        ]
        new_joints = []
        for m, choice in enumerate(chosen):
            joint = staged.joints[m]
            if choice is None:
                new_joints.append(joint)
                per_joint.append({})
                continue
            model, params, x, std, cond, fixed = choice
            if fixed:
                warnings.append(
                    f"joint {m + 1} ({joint.name}): the logs do not pin the torque constant down "
                    "(too little load torque against friction and noise); kept the model's "
                    f"{joint.drive.torque_constant:.4g} N m/A"
                )
            if cond > MAX_CONDITION:
                raise KinergyError(
                    f"joint {m + 1} ({joint.name}): the current regression is singular (condition "
                    f"{cond:.3g}): the log does not excite every friction term of model {model!r}"
                )
            kt = 1.0 / x[0]
            values = x[1:] * kt
            kt_std = std[0] / x[0] ** 2
            value_std = np.sqrt((std[1:] * kt) ** 2 + (x[1:] * kt_std * kt) ** 2)
            new_params = with_linear_parameters(model, params, values)
            for name, value in zip(get_model(model).linear, values, strict=True):
                if value < 0 and name not in ("gamma1",):
                    warnings.append(
                        f"joint {m + 1} ({joint.name}): friction {name} = {value:.3g} is negative"
                    )
            new_joints.append(
                dataclasses.replace(
                    joint,
                    drive=dataclasses.replace(
                        joint.drive, torque_constant=float(kt), friction=Friction(model, new_params)
                    ),
                )
            )
            per_joint.append(
                {
                    "torque_constant_std": float(kt_std),
                    "friction_std": {
                        name: float(s)
                        for name, s in zip(get_model(model).linear, value_std, strict=True)
                    },
                    "condition_current": cond,
                }
            )
        staged = staged.with_joints(new_joints)
    else:
        warnings.append(
            "the logs have no actual_current: torque constants and friction kept from the model"
        )
        per_joint = [{} for _ in range(n)]
    sources = dict(staged.sources)
    if has_ref:
        sources["drive_inertia"] = Source(
            "identified", "kinergy identify (sequential, UR5e eqs 7-9)"
        )
    if has_current:
        sources["torque_constant"] = Source(
            "identified", "kinergy identify (sequential, UR5e eqs 17-18)"
        )
        sources["friction"] = Source("identified", "kinergy identify (sequential, UR5e eqs 17-18)")
    identified = dataclasses.replace(staged, sources=sources)
    joints_out = tuple(
        SequentialJoint(
            name=joint.name,
            rotor_inertia=float(joint.drive.motor_inertia + joint.drive.reducer_inertia)
            if rotor[j] >= joint.drive.reducer_inertia
            else float(rotor[j]),
            rotor_inertia_std=None if np.isnan(rotor_std[j]) else float(rotor_std[j]),
            motor_inertia=joint.drive.motor_inertia,
            torque_constant=joint.drive.torque_constant,
            friction=friction_entry(joint),
            identified=j not in problems,
            problem=problems.get(j),
            **per_joint[j],
        )
        for j, joint in enumerate(identified.joints)
    )
    validation = validation_metrics(identified, datas)
    result_fit = SequentialFit(
        **vars(validation),
        samples=fit["samples"],
        logs=tuple(fit["logs"]),
        lag=tuple(fit["lag"]),
        warnings=tuple(warnings),
        condition_rotor_inertia=fit.get("condition_rotor_inertia"),
        friction_holding=tuple(fit["friction_holding"]) if "friction_holding" in fit else None,
    )
    return IdentificationResult(identified, "sequential", joints_out, result_fit)
