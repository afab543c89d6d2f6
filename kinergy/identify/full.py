"""The full method: one base-parameter regression of the links, the rotor inertias and friction.

Where the sequential method (:mod:`kinergy.identify.sequential`) keeps the model's link data and
identifies the drives step by step, the full method identifies everything the joint torques are
linear in at once (Gautier's base-parameter identification; nursing eqs 15-16 and the nursing
paper's ridge regression)::

    tau = Y_b(q, qd, qdd) pi_b + N^T diag(J) N qdd + N^T F(wm) phi                  (1)

- ``Y_b pi_b``: rigid-body torques in the base (minimal) inertial parameters of the links (nursing
  eqs 15-16; :func:`kinergy.dynamics.regressor.base_parameters` gives the structural set);
- ``N^T diag(J) N qdd``: motor plus reducer inertias ``J = J_m + J_r`` (motor side, kg m^2)
  reflected through the transmission ``N`` (UR5e eq 2, ``i^2 (J_m + J_r) qdd`` for a UR joint);
- ``N^T F(wm) phi``: motor-side friction, ``F`` the columns of each joint's friction model
  (:func:`kinergy.friction.registry.friction_columns`) at the motor speeds ``wm = N qd`` and ``phi``
  its linear parameters; shape parameters (smoothing, Stribeck speed, ...) stay the model's.

``tau`` is the signal chosen by ``target``:

``"moment"``
    ``target_moment`` on the commanded motion: the controller's feed-forward (UR5e eq 7), which has
    no friction, so (1) without its last term.
``"torque"``
    Measured joint torques (arms with joint torque sensors) on the real motion, with friction.
``"current"``
    ``actual_current`` on the real motion as joint torques through the model's torque constants,
    ``tau = N^T (k_t * I)`` (UR5e eq 17), with friction. A common scale of every parameter and of
    ``1/k_t`` cannot be told apart, so the torque constants stay the model's.

The columns of (1), stacked over every sample and joint, are checked for linear dependence by
column-scaled QR with column pivoting (Gautier's numerical rank), the link base columns first: a
rotor inertia can multiply the very signal a link base parameter does (on a UR arm ``J_1`` and the
``Iyy1`` group both multiply only ``qdd1`` on joint 1), and a friction term can go unexcited. Such
columns are dropped: their parameters keep the model's values and the parameters they merge into
absorb the difference (``fit["merged"]`` gives the combination, ``fit["warnings"]`` says so).

Solvers: ordinary least squares; Gautier's weighted least squares (the rows of joint ``j``
weighted by ``1 / sigma_j``, ``sigma_j`` its residual standard deviation after an OLS pass); ridge
regression on unit-norm columns shrinking toward the model's values (a weakly excited parameter
stays near its prior instead of collapsing to zero). Each regression is solved from one QR
factorisation of the column-scaled ``[A | y]``; everything after it works on the small triangle.

A robot file stores masses, centres of mass and inertias, not base parameters. The standard
parameters closest to the model's that reproduce the identified base parameters exactly are
written back (:func:`standard_from_base`). When one of those links is not physical
(:func:`link_consistency`) or a rotor inertia comes out negative, the robot is written from the
least-squares fit constrained to physically consistent links (pseudo-inertia positive definite,
Wensing et al. 2018) and non-negative rotor inertias instead: a small convex problem on the
regression's own triangle, solved by a log-barrier method; it reproduces the identified base
parameters exactly whenever they have a physical realisation. Every non-physical link is named in
``fit["warnings"]``; a link that still cannot be made physical keeps the model's data.
"""

from __future__ import annotations

import dataclasses
import itertools
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import scipy.linalg
import scipy.optimize
from numpy.typing import NDArray

from kinergy.drives.transmission import transmission_matrix
from kinergy.dynamics.regressor import (
    BaseParameters,
    base_parameters,
    inertial_parameters,
    parameter_names,
    regressor,
)
from kinergy.errors import KinergyError
from kinergy.friction.registry import (
    MODELS,
    friction_columns,
    get_model,
    linear_values,
    start_parameters,
    with_linear_parameters,
)
from kinergy.identify.metrics import JointMetrics, fit_metrics
from kinergy.identify.physical import (
    PSEUDO_BASIS,
    base_projection,
    link_consistency,
    link_from_standard,
    parameter_scale,
    pseudo_inertia,
    standard_from_base,
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
from kinergy.model.robot import Friction, Joint, Link, Robot, Source
from kinergy.predict import drive_state

__all__ = [
    "MAX_CONDITION",
    "SOLVERS",
    "TARGETS",
    "identify_full",
]

Array = NDArray[np.float64]

#: signals the regression can be made against; "auto" picks torque, else moment, else current
TARGETS = ("auto", "moment", "torque", "current")
#: least-squares variants
SOLVERS = ("ols", "wls", "ridge")
#: a joint whose speed never exceeds this (rad/s) counts as not moving
MOVING_SPEED = 0.05
#: the column-scaled stacked regressor, after merged columns are dropped, is singular beyond this
MAX_CONDITION = 1e10
#: a column whose part independent of the kept ones is below this fraction of its norm is dependent
DEPENDENT_TOL = 1e-8
#: samples needed per unknown parameter
SAMPLES_PER_PARAMETER = 2
#: friction models whose columns depend on the load torque (the direction of power flow)
_LOAD_DEPENDENT = ("power_flow",)
_MAX_FLOW_ITERATIONS = 10

_REF = "kinergy identify (full base-parameter regression, nursing eqs 15-16, UR5e eq 2)"


# ---------------------------------------------------------------------------------------------
# From base parameters back to links


@dataclass(frozen=True)
class Parameter:
    """One unknown of the regression: its value, standard error and relative standard error
    (None where not estimable) and, for the stacked unknowns, its group (``link``, ``rotor``,
    ``friction``)."""

    name: str
    value: float
    std: float | None
    rel_std: float | None
    group: str | None = field(default=None, metadata=OPTIONAL)


@dataclass(frozen=True)
class FullJoint(DriveEstimate):
    """A joint's drive from the full method: the rotor inertia's standard error, whether its
    column was merged into the link parameters, and the friction parameters' standard errors."""

    rotor_inertia_std: float | None = None
    rotor_inertia_merged: bool = False
    friction_std: dict[str, float | None] = field(default_factory=dict)


@dataclass(frozen=True)
class FullFit(Fit):
    """The full method's fit (module docstring): the regression's settings and condition, its
    unknowns with standard errors, merged columns, and how the robot was written back."""

    target: str = ""
    solver: str = "ols"
    ridge: float = 0.0
    condition: float = float("nan")
    power_flow_iterations: int = 0
    power_flow_mismatch: int = 0
    weights: tuple[float, ...] | None = field(default=None, metadata=OPTIONAL)
    condition_weighted: float | None = field(default=None, metadata=OPTIONAL)
    residual_std: tuple[float, ...] = ()
    regression: tuple[JointMetrics, ...] = ()
    merged: tuple[dict[str, Any], ...] = ()
    parameters: tuple[Parameter, ...] = ()
    base_parameters: tuple[Parameter, ...] = ()
    physical_fit: dict[str, Any] | None = field(default=None, metadata=OPTIONAL)
    write_back: str = "closest"
    links_not_physical_closest: tuple[int, ...] = ()
    links_physical: tuple[bool, ...] = ()
    standard_parameters: dict[str, float] = field(default_factory=dict)


@dataclass(frozen=True)
class _Reduced:
    """``[A_s | y] = Q r`` with ``A_s = A / scale``: ``r`` (p + 1, p + 1) upper triangular."""

    r: Array
    scale: Array
    rows: int

    @property
    def r_a(self) -> Array:
        return self.r[:, :-1]

    @property
    def r_y(self) -> Array:
        return self.r[:, -1]


def _reduce(a: Array, y: Array) -> _Reduced:
    """One QR factorisation of the column-scaled (unit-norm) regressor with the target appended:
    every least-squares quantity follows from the small triangle (``|y - A_s z| = |r_y - r_a z|``)."""
    scale = np.linalg.norm(a, axis=0)
    scale[scale == 0.0] = 1.0
    m = np.empty((a.shape[0], a.shape[1] + 1), order="F")
    np.divide(a, scale, out=m[:, :-1])
    m[:, -1] = y
    if m.shape[0] < m.shape[1]:
        raise KinergyError(f"{m.shape[0]} equations for {a.shape[1]} parameters")
    # LAPACK geqrf in place (Fortran order): R is the upper triangle of the first p + 1 rows
    qr, _, _, info = scipy.linalg.lapack.dgeqrf(np.asfortranarray(m), overwrite_a=True)
    if info != 0:  # pragma: no cover - LAPACK argument error
        raise KinergyError(f"QR factorisation failed (LAPACK info {info})")
    return _Reduced(np.triu(qr[: m.shape[1]]), scale, a.shape[0])


@dataclass(frozen=True)
class _Solution:
    """Solution ``x``, standard deviations (original units), condition number of the
    column-scaled regressor, residual sum of squares."""

    x: Array
    std: Array
    cond: float
    sse: float


def _solve(
    r_a: Array, r_y: Array, rows: int, z0: Array | None = None, lam: float = 0.0
) -> _Solution:
    """Least squares (``lam = 0``) or ridge toward ``z0``, in scaled coordinates ``z``.

    ``r_a`` (k + 1, m) and ``r_y`` (k + 1,) are the reduced problem (:class:`_Reduced`, columns
    possibly a subset). Ridge minimises ``|y - A_s z|^2 + lam |z - z0|^2``. Covariances:
    ``sigma^2 (A_s^T A_s)^-1`` for least squares, the ridge estimator's
    ``sigma^2 V diag(s^2 / (s^2 + lam)^2) V^T`` otherwise, ``sigma^2`` the residual sum of squares
    over ``rows - effective parameters``; returned in ``z`` (the caller unscales).
    """
    u, s, vt = np.linalg.svd(r_a, full_matrices=False)
    cond = float(s[0] / s[-1]) if s[-1] > 0 else float("inf")
    base = np.zeros(r_a.shape[1]) if z0 is None or lam == 0.0 else z0
    uty = u.T @ (r_y - r_a @ base)
    with np.errstate(divide="ignore"):
        gain = s / (s**2 + lam) if lam > 0.0 else np.where(s > 0, 1.0 / s, 0.0)
    z = base + vt.T @ (gain * uty)
    p_eff = float(np.sum(s * gain))
    resid = r_y - r_a @ z
    sse = float(resid @ resid)
    sigma2 = sse / max(rows - p_eff, 1.0)
    std = np.sqrt(sigma2 * np.sum((vt.T * gain) ** 2, axis=1))
    return _Solution(z, std, cond, sse)


def _friction_block(
    n_mat: Array,
    models: list[str],
    params: list[dict[str, float]],
    wm: Array,
    dwm: Array,
    load: Array,
    starts: Array,
) -> Array:
    """Joint-side friction columns ``N^T F``, shape (N, n, k).

    ``wm``, ``dwm``, ``load`` (N, n) are motor side; columns are built log by log (``starts``
    bounds them) so friction held through standstill sees each log's samples in time order.
    """
    n = n_mat.shape[0]
    widths = [len(get_model(m).linear) for m in models]
    out = np.zeros((wm.shape[0], n, sum(widths)))
    col = 0
    for m in range(n):
        if widths[m] == 0:
            continue
        f = np.vstack(
            [
                friction_columns(models[m], params[m], wm[a:b, m], load[a:b, m], dwm[a:b, m])
                for a, b in itertools.pairwise(starts)
            ]
        )
        # motor m's friction reaches joint j through N[m, j]
        out[:, :, col : col + widths[m]] = n_mat[m][None, :, None] * f[:, None, :]
        col += widths[m]
    return out


def _power_flow_load(
    models: list[str],
    params: list[dict[str, float]],
    values: list[Array],
    wm: Array,
    dwm: Array,
    tau_m: Array,
    previous: Array,
    margin: Array,
    starts: Array,
) -> Array:
    """Load torques (motor side, (N, n)) that set the friction's power-flow direction.

    The load is the measured motor torque less the friction, ``tau_load = tau_m - f`` (UR5e eqs
    12-17), and the friction depends on the direction: a sample is "direct" when
    ``wm (tau_m - f_direct) > margin |wm|`` and "reverse" when ``wm (tau_m - f_reverse) <
    -margin |wm|``; where both or neither hold, ``previous`` decides. With the true friction this
    is the true direction whatever the link parameters, so iterating it with the fitted friction
    settles; iterating the fitted model's own load torque instead does not (near a load zero
    crossing the friction jumps by ``coulomb_direct - coulomb_reverse``, and small parameter errors
    flip samples that pull the fit further). Deciding by the measurement ties the regressor to the
    measurement's noise where the load is within the noise of zero: a small bias (limitations in
    :func:`identify_full`).

    Parameters
    ----------
    values : list of ndarray
        Each motor's friction levels (the model's ``linear`` parameters, :mod:`kinergy.friction`).
    wm, dwm, tau_m, previous : ndarray, shape (N, n)
        Motor speeds (rad/s), accelerations (rad/s^2), measured motor torques and the loads of the
        previous pass (N m, motor side).
    margin : ndarray, shape (n,)
        N m, motor side; 0 trusts the measurement wherever it is unambiguous.
    starts : ndarray of int
        Log boundaries (friction held through standstill needs each log in time order).
    """
    out = previous.copy()
    for m, model in enumerate(models):
        if model not in _LOAD_DEPENDENT:
            continue
        for a, b in itertools.pairwise(starts):
            w, acc, meas = wm[a:b, m], dwm[a:b, m], tau_m[a:b, m]
            direction = np.sign(w)
            load_dir = meas - friction_columns(model, params[m], w, direction, acc) @ values[m]
            load_rev = meas - friction_columns(model, params[m], w, -direction, acc) @ values[m]
            is_dir = w * load_dir > margin[m] * np.abs(w)
            is_rev = w * load_rev < -margin[m] * np.abs(w)
            out[a:b, m] = np.where(
                is_dir & ~is_rev, load_dir, np.where(is_rev & ~is_dir, load_rev, previous[a:b, m])
            )
    return out


def _check_link_rank(r_link: Array, expressions: list[str]) -> None:
    """Raise when the link base columns (their triangle ``r_link``, (b, b)) are rank deficient."""
    _, r, piv = scipy.linalg.qr(r_link, pivoting=True)
    diag = np.abs(np.diag(r))
    rank = int(np.sum(diag > 1e-10 * max(float(diag[0]), 1e-300)))
    if rank < r_link.shape[1]:
        deficient = np.sort(piv[rank:])
        listed = "; ".join(expressions[k] for k in deficient[:4])
        more = f" and {deficient.size - 4} more" if deficient.size > 4 else ""
        raise KinergyError(
            f"the logs do not excite {deficient.size} link base parameter(s) ({listed}{more}): "
            "use a richer excitation (more joints moving together, more harmonics)"
        )


def _dependent_extras(r_extra: Array) -> Array:
    """Rotor and friction columns that depend on the link columns or on earlier extras.

    ``r_extra`` is the extras' block of the triangle below the link rows, i.e. the R factor of
    their unit-norm parts orthogonal to the link columns; pivoted QR of it finds the columns whose
    remaining part is below :data:`DEPENDENT_TOL` (Gautier's numerical rank, link columns kept
    first). Returns sorted indices into the extras.
    """
    if r_extra.shape[1] == 0:
        return np.zeros(0, dtype=int)
    _, r, piv = scipy.linalg.qr(r_extra, pivoting=True)
    diag = np.abs(np.diag(r))
    rank = int(np.sum(diag > DEPENDENT_TOL))
    return np.sort(piv[rank:])


def _singular(r_a: Array, cond: float, names: list[str]) -> KinergyError:
    """The error for an ill-conditioned regression, naming the parameters of its weakest
    direction (largest entries of the last right singular vector of the scaled columns)."""
    _, _, vt = np.linalg.svd(r_a)
    weak = np.argsort(-np.abs(vt[-1]))[:4]
    return KinergyError(
        f"the stacked regressor is singular (condition {cond:.3g} > {MAX_CONDITION:g}): the logs "
        "barely excite " + ", ".join(names[i] for i in weak)
    )


def _diagnose(robot: Robot, qd: Array, n_params: int) -> None:
    """One line naming what the logs cannot identify: too few samples, joints that never move."""
    problems = []
    samples = qd.shape[0]
    need = SAMPLES_PER_PARAMETER * n_params
    if samples < need:
        problems.append(f"only {samples} samples for {n_params} parameters (need at least {need})")
    for j, joint in enumerate(robot.joints):
        top = float(np.max(np.abs(qd[:, j]))) if samples else 0.0
        if top < MOVING_SPEED:
            problems.append(
                f"joint {j + 1} ({joint.name}) never moves (max |qd| {top:.3g} rad/s): its link, "
                "rotor inertia and friction parameters cannot be identified"
            )
    if problems:
        raise KinergyError("cannot identify from these logs: " + "; ".join(problems))


def _pick_target(datas: Sequence[IdentData], target: str) -> str:
    if target not in TARGETS:
        raise KinergyError(f"unknown target {target!r} (known: {', '.join(TARGETS)})")
    field = {"moment": "tau_ref", "torque": "torque", "current": "current"}
    if target == "auto":
        for name in ("torque", "moment", "current"):
            if all(getattr(d, field[name]) is not None for d in datas):
                return name
        raise KinergyError(
            "the full method needs measured joint torques, target_moment or actual_current in "
            "every log; the logs have none of them in common"
        )
    signal = {
        "moment": "target_moment",
        "torque": "measured joint torques",
        "current": "actual_current",
    }
    missing = [d.path for d in datas if getattr(d, field[target]) is None]
    if missing:
        raise KinergyError(
            f"target {target!r} needs {signal[target]}, missing in {', '.join(missing)}"
        )
    return target


def _check_options(solver: str, ridge: float, friction: str | None) -> None:
    if solver not in SOLVERS:
        raise KinergyError(f"unknown solver {solver!r} (known: {', '.join(SOLVERS)})")
    if isinstance(ridge, bool) or not isinstance(ridge, int | float) or not np.isfinite(ridge):
        raise KinergyError(f"ridge must be a finite number, got {ridge!r}")
    if ridge < 0.0:
        raise KinergyError(f"ridge must be >= 0, got {ridge:g}")
    if solver == "ridge" and ridge == 0.0:
        raise KinergyError("solver 'ridge' needs ridge > 0 (the weight of the prior, e.g. 1e-4)")
    if solver != "ridge" and ridge != 0.0:
        raise KinergyError(f"ridge = {ridge:g} is only used by solver 'ridge', not {solver!r}")
    if friction is not None and friction not in MODELS:
        raise KinergyError(
            f"unknown friction model {friction!r} (known: {', '.join(sorted(MODELS))})"
        )


@dataclass(frozen=True)
class _Columns:
    """What each column of the stacked regression is: [link base | rotor | friction]."""

    names: list[str]
    group: list[str]
    prior: Array
    n_link: int
    fric_at: Array  # column range of motor m's friction: fric_at[m]:fric_at[m + 1]


def _columns(
    robot: Robot, base: BaseParameters, models: list[str], params: list[dict[str, float]]
) -> _Columns:
    n = robot.n
    widths = [len(get_model(m).linear) for m in models]
    short = [base.names[k] for k in base.independent]
    joint = [f"joint {m + 1} ({j.name})" for m, j in enumerate(robot.joints)]
    prior = np.concatenate(
        [
            base.project(inertial_parameters(robot)),
            [j.drive.rotor_inertia for j in robot.joints],
            *[linear_values(models[m], params[m]) for m in range(n)],
        ]
    )
    return _Columns(
        names=[f"base parameter {s}" for s in short]
        + [f"rotor inertia of {joint[m]}" for m in range(n)]
        + [f"friction {p} of {joint[m]}" for m in range(n) for p in get_model(models[m]).linear],
        group=["link"] * base.size + ["rotor"] * n + ["friction"] * sum(widths),
        prior=prior,
        n_link=base.size,
        fric_at=base.size + n + np.cumsum([0, *widths]),
    )


def identify_full(
    robot: Robot,
    datas: Sequence[IdentData],
    *,
    target: str = "auto",
    solver: str = "ols",
    ridge: float = 0.0,
    friction: str | None = None,
) -> IdentificationResult:
    """Identify link base parameters, rotor inertias and friction in one regression.

    Solves, stacked over every sample and joint of every log, the linear model (module docstring,
    eq (1))::

        tau = Y_b pi_b + N^T diag(J) N qdd + N^T F(wm) phi

    with ``pi_b`` the links' base parameters (nursing eqs 15-16), ``J = J_m + J_r`` the rotor
    inertias (motor side, kg m^2; UR5e eq 2) and ``phi`` the friction models' linear parameters
    (motor side), then writes standard link parameters that reproduce ``pi_b`` back into the model
    (:func:`standard_from_base`, :func:`link_consistency`; module docstring).

    Parameters
    ----------
    robot : Robot
        The starting model: its kinematics, transmissions, torque constants and friction shape
        parameters are used as they are; its link data, rotor inertias and friction levels are
        the priors (kept where the logs cannot identify them, shrunk toward by ridge).
    datas : sequence of IdentData
        Prepared logs (:func:`kinergy.identify.preprocess.prepare`), arrays (N, n).
    target : {"auto", "moment", "torque", "current"}
        The signal regressed against: ``target_moment`` (N m) on the commanded motion without
        friction, measured joint torques (N m) or ``actual_current`` (A, times ``k_t``) on the real
        motion with friction. ``"auto"``: torque if every log has it, else moment, else current.
    solver : {"ols", "wls", "ridge"}
        Ordinary least squares; weighted least squares, per-joint weights ``1 / sigma_j^2`` from an
        OLS pass's residuals (Gautier); ridge regression toward the model's values.
    ridge : float
        The ridge weight ``lambda`` (``solver="ridge"`` only, > 0). Columns are scaled to unit
        norm, ``z_k = |A_k| x_k``, and ``|y - A_s z|^2 + lambda |z - z_model|^2`` is minimised:
        ``lambda`` compares with the unit diagonal of the scaled normal matrix, and a direction
        whose scaled singular value is below ``sqrt(lambda)`` stays near the model (1e-6 to 1e-2
        are typical).
    friction : str, optional
        Friction model for every joint (default: each joint's own). Its shape parameters are the
        joint's when the model is the same, else defaults (smoothing 1e-3 rad/s, ...). Unused for
        ``target="moment"`` (the feed-forward has no friction; the model's is kept).

    Returns
    -------
    IdentificationResult
        ``method = "full"``. ``joints``, per joint: ``rotor_inertia`` (kg m^2, motor side, as
        written to the returned robot), ``rotor_inertia_std`` (None when merged),
        ``rotor_inertia_merged``, ``motor_inertia`` (``rotor_inertia - reducer_inertia``; below
        the model's reducer inertia, 0 and the reducer inertia lowered to ``rotor_inertia``, with
        a warning), ``torque_constant`` (N m/A, the model's), ``friction`` ({"model",
        parameters}) and ``friction_std``. ``fit``:
        ``base_parameters`` ([{"name", "value", "std", "rel_std"}], names from
        :meth:`BaseParameters.expressions`), ``parameters`` (every column of the regression with
        its group), ``condition`` (column-scaled stacked regressor), ``merged`` (dropped columns:
        {"parameter", "value" kept, "into": [{"parameter", "index", "coefficient"}]}),
        ``residual_std`` (N m per joint, joint side), ``regression`` (per-joint mean, max, rms,
        r2 of the base-parameter model's prediction of the target in N m, joint side),
        ``torque``/``current``/``joint_torque`` (:func:`validation_metrics` of the returned robot
        on the same logs), ``write_back``, ``links_physical``, ``standard_parameters`` and
        ``warnings``; ``weights`` (1/sigma_j^2) with WLS.

    Raises
    ------
    KinergyError
        Unknown options; a target signal the logs lack; too few samples for the number of
        parameters; a joint that never moves; link base parameters the logs do not excite; a
        stacked regressor whose condition number exceeds :data:`MAX_CONDITION` (naming the
        weakest parameters).

    Notes
    -----
    Rotor-inertia and friction columns found dependent on the others keep the model's value; the
    parameters they merge into carry the difference (e.g. the ``Iyy1`` group carries
    ``i_1^2 (J_1 - J_1,model)`` on a UR arm). When the closest standard parameters are not
    physical or a rotor inertia is negative, the returned robot comes from the fit constrained to
    physical links and non-negative rotor inertias (``fit["write_back"]``, ``fit["physical_fit"]``
    with its chi^2 increase; merged rotor inertias may then move, the merged combinations keep
    their fit); a link still not physical keeps the model's data, and the returned robot then
    differs from the identified base parameters. ``fit["regression"]`` is always the
    unconstrained fit, ``fit["torque"]`` etc. the returned robot's. Only the friction models'
    linear parameters are fitted, and the torque constants never (module docstring).
    """
    if not datas:
        raise KinergyError("no log to identify from")
    _check_options(solver, ridge, friction)
    target = _pick_target(datas, target)
    n = robot.n
    n_mat = transmission_matrix(robot)
    commanded = target == "moment"
    names = ("q_cmd", "qd_cmd", "qdd_cmd") if commanded else ("q", "qd", "qdd")
    q, qd, qdd = (np.vstack([getattr(d, k) for d in datas]) for k in names)
    params = [
        start_parameters(
            friction or j.drive.friction.model, j.drive.friction.model, j.drive.friction.params
        )
        for j in robot.joints
    ]
    models = (
        ["none"] * n if commanded else [friction or j.drive.friction.model for j in robot.joints]
    )
    base = base_parameters(robot)
    cols = _columns(robot, base, models, params)
    n_link, n_cols = cols.n_link, cols.prior.size
    _diagnose(robot, qd, n_cols)
    samples = q.shape[0]

    # the target as joint torques, (N, n)
    if target == "moment":
        y3 = np.vstack([d.tau_ref for d in datas if d.tau_ref is not None])
    elif target == "torque":
        y3 = np.vstack([d.torque for d in datas if d.torque is not None])
    else:
        kt = np.array([j.drive.torque_constant for j in robot.joints])
        y3 = (np.vstack([d.current for d in datas if d.current is not None]) * kt) @ n_mat
    y = y3.reshape(-1)

    # regression columns; rows are (sample, joint)
    a_all = np.empty((samples, n, n_cols))
    a_all[:, :, :n_link] = base.regressor(regressor(robot, q, qd, qdd))
    wm, dwm = qd @ n_mat.T, qdd @ n_mat.T
    a_all[:, :, n_link : n_link + n] = n_mat.T[None, :, :] * dwm[:, None, :]  # N[m, j] (N qdd)_m
    a_flat = a_all.reshape(samples * n, n_cols)

    # power_flow friction needs the load torque's sign: start from the measurement less the
    # model's friction, then iterate with the fitted friction until the directions settle
    starts = np.cumsum([0] + [len(d) for d in datas])
    needs_load = any(m in _LOAD_DEPENDENT for m in models)
    tau_m = np.asarray(np.linalg.solve(n_mat.T, y3.T).T, dtype=float)  # measured, motor side
    load = np.zeros_like(q)
    if needs_load:
        predicted = np.asarray(drive_state(robot, q, qd, qdd).tau_load)
        prior_values = [cols.prior[cols.fric_at[m] : cols.fric_at[m + 1]] for m in range(n)]
        load = _power_flow_load(
            models, params, prior_values, wm, dwm, tau_m, predicted, np.zeros(n), starts
        )
    expressions = base.expressions()
    n_fixed = n_link + n  # columns that do not depend on the load torque

    def fit_with(load: Array, first: bool) -> tuple[_Reduced, Array, Array, _Solution, Array]:
        """OLS with the friction columns of these load torques: the reduced problem, dropped and
        kept columns, the solution, and all unknowns (dropped ones at the model's values)."""
        a_all[:, :, n_fixed:] = _friction_block(n_mat, models, params, wm, dwm, load, starts)
        red = _reduce(a_flat, y)
        if first:
            _check_link_rank(red.r[:n_link, :n_link], expressions)
        dropped = n_link + _dependent_extras(red.r[n_link:n_cols, n_link:n_cols])
        kept = np.setdiff1d(np.arange(n_cols), dropped)
        z_prior = cols.prior * red.scale
        r_y = red.r_y - red.r_a[:, dropped] @ z_prior[dropped]
        ols = _solve(red.r_a[:, kept], r_y, red.rows)
        if ols.cond > MAX_CONDITION:
            raise _singular(red.r_a[:, kept], ols.cond, [cols.names[k] for k in kept])
        x_all = cols.prior.copy()
        x_all[kept] = ols.x / red.scale[kept]
        return red, dropped, kept, ols, x_all

    def own_load(x_all: Array) -> Array:
        """The load torques a model with unknowns ``x_all`` predicts itself (motor side)."""
        tau_sim = (a_flat[:, :n_fixed] @ x_all[:n_fixed]).reshape(samples, n)
        return np.asarray(np.linalg.solve(n_mat.T, tau_sim.T).T)

    # power-flow directions from the measurement less the fitted friction, until they settle
    iterations, settled = 0, not needs_load
    while True:
        iterations += 1
        red, dropped, kept, ols, x_it = fit_with(load, iterations == 1)
        if settled or iterations >= _MAX_FLOW_ITERATIONS:
            break
        values = [x_it[cols.fric_at[m] : cols.fric_at[m + 1]] for m in range(n)]
        new = _power_flow_load(models, params, values, wm, dwm, tau_m, load, np.zeros(n), starts)
        settled = bool(np.array_equal(np.sign(wm * new), np.sign(wm * load)))
        if settled:
            break
        load = new

    warnings: list[str] = []
    if not settled:
        warnings.append(
            f"the friction's power-flow directions did not settle in {iterations} iterations"
        )
    mismatch = 0
    if needs_load:  # how often the fitted model's own load torque disagrees with the one used
        mismatch = int(np.sum(np.sign(wm * own_load(x_it)) != np.sign(wm * load)))
    fit: dict[str, Any] = {
        "target": target,
        "solver": solver,
        "ridge": float(ridge),
        "samples": int(samples),
        "logs": [d.path for d in datas],
        "lag": [d.lag for d in datas],
        "condition": ols.cond,
        "power_flow_iterations": iterations if needs_load else 0,
        "power_flow_mismatch": mismatch,
    }

    # the chosen solver
    rows_joint = np.tile(np.arange(n), samples)
    used, lam = red, 0.0
    sol = ols
    if solver == "wls":
        x_ols = cols.prior.copy()
        x_ols[kept] = ols.x / red.scale[kept]
        resid = y - a_flat @ x_ols
        dof_share = max(1.0 - kept.size / red.rows, 1e-9)
        sigma = np.sqrt(np.bincount(rows_joint, resid**2, minlength=n) / (samples * dof_share))
        if np.any(sigma > 0.0):
            w_j = 1.0 / np.maximum(sigma, 1e-9 * float(sigma.max()))
        else:  # noise-free data: nothing to weigh
            w_j = np.ones(n)
        w = w_j[rows_joint]
        used = _reduce(a_flat * w[:, None], y * w)
        r_y = used.r_y - used.r_a[:, dropped] @ (cols.prior * used.scale)[dropped]
        sol = _solve(used.r_a[:, kept], r_y, used.rows)
        fit["weights"] = tuple((w_j**2).tolist())
        fit["condition_weighted"] = sol.cond
    elif solver == "ridge":
        lam = float(ridge)
        z_prior = cols.prior * red.scale
        r_y = red.r_y - red.r_a[:, dropped] @ z_prior[dropped]
        sol = _solve(red.r_a[:, kept], r_y, red.rows, z_prior[kept], lam)
    x = cols.prior.copy()
    x[kept] = sol.x / used.scale[kept]
    std = np.full(n_cols, np.nan)
    std[kept] = sol.std / used.scale[kept]
    predicted3 = (a_flat @ x).reshape(samples, n)
    fit["residual_std"] = tuple(np.sqrt(np.mean((y3 - predicted3) ** 2, axis=0)).tolist())
    fit["regression"] = fit_metrics(y3, predicted3)

    # dropped (merged) columns: each as a combination of the kept ones
    merged = []
    merged_rotor: dict[int, Array] = {}  # motor -> its column in link base columns, (b,)
    if dropped.size:
        scale = red.scale
        coef_s = np.linalg.lstsq(red.r_a[:, kept], red.r_a[:, dropped], rcond=None)[0]
        coef = coef_s * scale[dropped][None, :] / scale[kept][:, None]
        excited = np.linalg.norm(red.r_a[:, dropped], axis=0) > 0
        for i, k in enumerate(dropped):
            text, entry = _merge_note(int(k), cols, kept, coef[:, i] if excited[i] else None)
            warnings.append(text)
            merged.append(entry)
            into = entry["into"]
            if cols.group[k] == "rotor" and into and all(e["index"] < n_link for e in into):
                c_vec = np.zeros(n_link)
                for e in into:
                    c_vec[e["index"]] = e["coefficient"]
                merged_rotor[int(k - n_link)] = c_vec
    fit["merged"] = tuple(merged)

    with np.errstate(divide="ignore", invalid="ignore"):
        rel = np.abs(std) / np.abs(x)

    def described(name: str, k: int, group: str | None = None) -> Parameter:
        return Parameter(
            name=name,
            value=float(x[k]),
            std=None if np.isnan(std[k]) else float(std[k]),
            rel_std=None if np.isnan(rel[k]) else float(rel[k]),
            group=group,
        )

    fit["parameters"] = tuple(described(cols.names[k], k, cols.group[k]) for k in range(n_cols))
    fit["base_parameters"] = tuple(described(name, k) for k, name in enumerate(base.expressions()))

    problem = _Problem(used, kept, dropped, lam, sol.sse / max(used.rows - kept.size, 1))
    identified, x_written = _write_back(
        robot, base, x, cols, models, params, commanded, merged_rotor, problem, warnings, fit
    )
    if "physical_fit" in fit:
        fit["physical_fit"]["regression"] = fit_metrics(
            y3, (a_flat @ x_written).reshape(samples, n)
        )
    validation = validation_metrics(identified, datas)
    fit.update(vars(validation))
    fit["warnings"] = tuple(warnings)
    fit["logs"], fit["lag"] = tuple(fit["logs"]), tuple(fit["lag"])

    joints_out = []
    for m, joint in enumerate(identified.joints):
        col = n_link + m
        fric = slice(cols.fric_at[m], cols.fric_at[m + 1])
        joints_out.append(
            FullJoint(
                name=joint.name,
                rotor_inertia=float(x_written[col]),
                rotor_inertia_std=None if np.isnan(std[col]) else float(std[col]),
                rotor_inertia_merged=bool(col in dropped),
                motor_inertia=joint.drive.motor_inertia,
                torque_constant=joint.drive.torque_constant,
                friction=friction_entry(joint),
                friction_std={
                    name: None if np.isnan(s) else float(s)
                    for name, s in zip(get_model(models[m]).linear, std[fric], strict=True)
                },
            )
        )
    return IdentificationResult(identified, "full", tuple(joints_out), FullFit(**fit))


def _merge_note(
    k: int, cols: _Columns, kept: Array, coef: Array | None
) -> tuple[str, dict[str, Any]]:
    """Warning text and ``fit["merged"]`` entry for a dropped column (``coef``: its column as a
    combination of the kept columns, ``None`` when it is zero)."""
    name, value = cols.names[k], float(cols.prior[k])
    unit = " kg m^2" if cols.group[k] == "rotor" else " (motor side)"
    if coef is None:
        text = f"{name} is not excited by the logs (its column is zero): kept the model's {value:.4g}{unit}"
        return text, {"parameter": name, "value": value, "into": []}
    order = np.argsort(-np.abs(coef))
    into = [
        {"parameter": cols.names[kept[i]], "index": int(kept[i]), "coefficient": float(coef[i])}
        for i in order
        if abs(coef[i]) > 1e-9 * np.abs(coef).max()
    ]
    shown = " ".join(f"{e['coefficient']:+.4g}*[{e['parameter']}]" for e in into[:3])
    more = f" and {len(into) - 3} more" if len(into) > 3 else ""
    text = (
        f"{name} cannot be told apart from the other parameters (its column = {shown}{more}): "
        f"merged into them, kept the model's {value:.4g}{unit}"
    )
    return text, {"parameter": name, "value": value, "into": into}


@dataclass(frozen=True)
class _Problem:
    """The solved regression, for the physically consistent refit: its reduced triangle (of the
    weighted problem for WLS), kept and dropped columns, ridge weight, residual variance."""

    reduced: _Reduced
    kept: Array
    dropped: Array
    lam: float
    sigma2: float


def _barrier_lsq(
    r0: Array,
    jac: Array,
    c_blocks: Array,
    b_blocks: Array,
    a_vec: Array,
    r_mat: Array,
    u0: Array,
    gap: float = 1e-3,
) -> Array | None:
    """``min |r0 + jac u|^2`` subject to ``C_l + sum_k u_k B_lk > 0`` (symmetric blocks) and
    ``a + R u > 0``, from a strictly feasible ``u0``: a log-barrier interior-point method with
    Newton steps (Boyd & Vandenberghe, Convex Optimization, section 11.3), stopped when the
    barrier's duality gap is below ``gap``. ``c_blocks`` (L, d, d), ``b_blocks`` (L, K, d, d).
    Returns ``None`` when ``u0`` is not strictly feasible or Newton fails."""
    gtg, gtr = jac.T @ jac, jac.T @ r0
    m = c_blocks.shape[0] * c_blocks.shape[1] + a_vec.size  # barrier weight count

    def blocks(u: Array) -> Array:
        return c_blocks + np.einsum("k,lkab->lab", u, b_blocks)

    def barrier(u: Array) -> float:
        slack = a_vec + r_mat @ u
        if np.any(slack <= 0):
            return np.inf
        eig = np.linalg.eigvalsh(blocks(u))
        if np.any(eig <= 0):
            return np.inf
        return float(-np.sum(np.log(eig)) - np.sum(np.log(slack)))

    def objective(u: Array) -> float:
        r = r0 + jac @ u
        return float(r @ r)

    u = u0.copy()
    if not np.isfinite(barrier(u)):
        return None
    t = m / max(objective(u), 1e-6)
    for _ in range(60):  # outer: t grows tenfold each time
        for _ in range(100):  # Newton on t f + barrier
            inv = np.linalg.inv(blocks(u))
            mk = np.einsum("lab,lkbc->lkac", inv, b_blocks)  # X^-1 B_k
            slack = a_vec + r_mat @ u
            grad = 2.0 * t * (gtg @ u + gtr) - np.einsum("lkaa->k", mk) - r_mat.T @ (1.0 / slack)
            hess = (
                2.0 * t * gtg
                + np.einsum("lkab,lmba->km", mk, mk)
                + (r_mat / slack[:, None] ** 2).T @ r_mat
            )
            try:
                step = -np.linalg.solve(hess, grad)
            except np.linalg.LinAlgError:
                return None
            decrement = float(-grad @ step)
            if decrement / 2.0 < 1e-9:
                break
            value = t * objective(u) + barrier(u)
            size = 1.0
            while size > 1e-12:
                trial = u + size * step
                if t * objective(trial) + barrier(trial) <= value - 0.25 * size * decrement:
                    break
                size *= 0.5
            else:
                break
            u = trial
        if m / t < gap:
            return u
        t *= 10.0
    return u


def _physical_fit(
    problem: _Problem,
    base: BaseParameters,
    cols: _Columns,
    x: Array,
    pi0: Array,
    scale: Array,
    payload: Array,
    merged_rotor: dict[int, Array],
    eps: float = 1e-3,
) -> tuple[Array, Array, float] | None:
    """Least squares constrained to physical links and non-negative rotor inertias.

    The regression's cost grows from its minimum ``x_hat`` (kept unknowns) as
    ``(x - x_hat)^T H (x - x_hat)``, ``H`` from the reduced triangle (``(R^T R + lambda 1) /
    sigma^2`` in scaled unknowns); with ``x - x_hat = V Lambda^-1/2 eta`` (``H = V Lambda V^T``)
    that is ``|eta|^2``, a chi^2 increase. The link base parameters ``theta`` are ``x``'s first
    ``b``; the standard parameters are ``pi = pi_s(theta - C dJ) + S Z t``
    (:func:`standard_from_base` plus the null space ``Z`` of ``P S``; ``C dJ`` moves merged rotor
    inertias, ``dJ = J_model delta``), and ::

        |eta|^2 + eps (|S^-1 (pi_s - pi0)|^2 + |t|^2 + |delta|^2)

    is minimised subject to every link's pseudo-inertia (:func:`pseudo_inertia`) staying above
    1e-3 times the model's smallest eigenvalue and every rotor inertia being >= 0 (a convex
    problem: linear matrix inequalities, solved by :func:`_barrier_lsq` from the model, which is
    feasible); ``eps`` only settles what the data cannot see.

    Returns
    -------
    (pi, x, chi2) or None
        Standard parameters (p,), the regression unknowns they go with (all columns), and the
        chi^2 increase ``|eta|^2``; ``None`` when the solver fails.
    """
    n_link, p = cols.n_link, pi0.size
    red, kept = problem.reduced, problem.kept
    s = red.scale[kept]
    # noise-free data: a floor at 1e-9 of the signal keeps H finite
    sigma2 = max(problem.sigma2, 1e-18 * float(red.r_y @ red.r_y) / red.rows, 1e-300)
    r_k = red.r_a[:, kept]
    # information in the scaled unknowns z = s x (unit-norm columns: well conditioned)
    hess = (r_k.T @ r_k + problem.lam * np.eye(kept.size)) / sigma2
    lam_h, vec_h = np.linalg.eigh(0.5 * (hess + hess.T))
    if lam_h[0] <= 0:
        return None
    m_mat = vec_h / np.sqrt(lam_h) / s[:, None]  # x[kept] - x_hat[kept] = m_mat @ eta
    p_mat = base_projection(base, p)
    k_mat = (scale**2)[:, None] * p_mat.T @ np.linalg.inv((p_mat * scale**2) @ p_mat.T)  # pi_s
    _, sv, vt = np.linalg.svd(p_mat * scale)
    z_null = vt[int(np.sum(sv > 1e-12 * sv[0])) :].T  # orthonormal, scaled coordinates
    motors = sorted(merged_rotor)
    j0 = np.array([cols.prior[n_link + m] for m in motors])
    j_unit = np.where(j0 > 0, j0, 1e-6)
    c_dj = (
        np.column_stack([merged_rotor[m] for m in motors]) * j_unit
        if motors
        else np.zeros((n_link, 0))
    )
    nk, nt, nd = kept.size, z_null.shape[1], len(motors)
    theta_hat = x[:n_link]
    # pi = pi_a + b_mat @ u, u = [eta, t, delta]; theta = theta_hat + m_mat[:b] eta - c_dj delta
    km = k_mat @ m_mat[:n_link]
    pi_a = pi0 + k_mat @ (theta_hat - p_mat @ pi0)
    b_mat = np.hstack([km, scale[:, None] * z_null, -k_mat @ c_dj])
    root = np.sqrt(eps)
    r0 = np.concatenate([np.zeros(nk), root * (pi_a - pi0) / scale, np.zeros(nt + nd)])
    jac = np.zeros((nk + p + nt + nd, nk + nt + nd))
    jac[:nk, :nk] = np.eye(nk)
    jac[nk : nk + p, :nk] = root * km / scale[:, None]
    jac[nk : nk + p, nk + nt :] = -root * (k_mat @ c_dj) / scale[:, None]
    jac[nk + p :, nk:] = root * np.eye(nt + nd)
    # start from the model, each link thickened by 1e-6 of its largest pseudo-inertia eigenvalue
    # (a flat model link, e.g. a thin disc, sits on the boundary; the barrier needs the inside);
    # links: pseudo-inertia(pi - payload) > 1e-3 times the start's smallest eigenvalue
    n_links = p // 10
    eig0 = np.linalg.eigvalsh(pseudo_inertia(pi0 - payload))
    if np.any(eig0[:, 0] < -1e-9 * eig0[:, -1]):
        return None
    pi_start = pi0.copy()
    for link in range(n_links):  # Sigma + e 1  <=>  Ixx, Iyy, Izz + 2 e
        pi_start[10 * link + np.array([4, 6, 9])] += 2e-6 * eig0[link, -1]
    ref = np.linalg.eigvalsh(pseudo_inertia(pi_start - payload))[:, 0]
    c_blocks = pseudo_inertia(pi_a - payload) / ref[:, None, None] - 1e-3 * np.eye(4)
    b_blocks = np.einsum("lpk,pab->lkab", b_mat.reshape(n_links, 10, -1), PSEUDO_BASIS)
    b_blocks /= ref[:, None, None, None]
    # rotor inertias, affine in u (kept ones through eta, merged ones through delta), >= 0
    # (>= -1e-3 of their size for the barrier's strict start; clipped to 0 after)
    rotor_rows = np.flatnonzero([cols.group[k] == "rotor" for k in kept])
    rot_a = np.concatenate([x[kept[rotor_rows]], j0])
    rot_b = np.zeros((rotor_rows.size + nd, nk + nt + nd))
    rot_b[: rotor_rows.size, :nk] = m_mat[rotor_rows]
    rot_b[rotor_rows.size :, nk + nt :] = np.diag(j_unit)
    rot_scale = np.maximum(np.abs(np.concatenate([cols.prior[kept[rotor_rows]], j0])), 1e-9)
    u0 = np.zeros(nk + nt + nd)  # pi_start, the model's rotor inertias and friction
    x0 = cols.prior[kept].copy()
    x0[:n_link] = p_mat @ pi_start
    u0[:nk] = np.sqrt(lam_h) * (vec_h.T @ (s * (x0 - x[kept])))
    pi_u0 = pi_a + b_mat[:, :nk] @ u0[:nk]  # = pi_s(P pi_start); the rest is null space
    u0[nk : nk + nt] = z_null.T @ ((pi_start - pi_u0) / scale)
    u = _barrier_lsq(
        r0,
        jac,
        c_blocks,
        b_blocks,
        rot_a / rot_scale + 1e-3,
        rot_b / rot_scale[:, None],
        u0,
    )
    if u is None:
        return None
    pi = pi_a + b_mat @ u
    if any(e is not None for e in link_consistency(pi - payload)):
        return None
    out = x.copy()
    out[kept] = x[kept] + m_mat @ u[:nk]
    out[:n_link] = p_mat @ pi
    if motors:
        out[n_link + np.array(motors)] = j0 + j_unit * u[nk + nt :]
    n_rot = cols.group.count("rotor")
    out[n_link : n_link + n_rot] = np.maximum(out[n_link : n_link + n_rot], 0.0)
    return pi, out, float(u[:nk] @ u[:nk])


def _write_back(
    robot: Robot,
    base: BaseParameters,
    x: Array,
    cols: _Columns,
    models: list[str],
    params: list[dict[str, float]],
    commanded: bool,
    merged_rotor: dict[int, Array],
    problem: _Problem,
    warnings: list[str],
    fit: dict[str, Any],
) -> tuple[Robot, Array]:
    """The identified robot, and the regression unknowns it was written from.

    Links: (1) the standard parameters closest to the model's with the identified base parameters
    (:func:`standard_from_base`); when one of those links is not physical, or a rotor inertia is
    negative, (2) the least-squares fit constrained to physical links and non-negative rotor
    inertias (:func:`_physical_fit`: the identified base parameters exactly when they have a
    physical realisation, else the nearest in the fit's own metric); (3) the model's data for a
    link still not physical. Rotor inertias give ``motor_inertia = J - reducer_inertia`` (UR5e
    eq 9, Table IV; below the reducer inertia, the reducer inertia gives way so the written
    ``J_m + J_r`` is the identified one); friction levels the joints' friction parameters.
    """
    n_link, n = cols.n_link, robot.n
    x_fit = x
    pi0 = inertial_parameters(robot)
    payload = pi0 - inertial_parameters(robot, include_payload=False)  # the last link's part
    scale = parameter_scale(robot)
    pi = standard_from_base(base, x[:n_link], pi0, scale=scale)
    problems = link_consistency(pi - payload)
    flagged = {j: p for j, p in enumerate(problems) if p is not None}
    negative = [m for m in range(n) if x[n_link + m] < 0.0]
    method = "closest"
    if flagged or negative:
        refit = _physical_fit(problem, base, cols, x, pi0, scale, payload, merged_rotor)
        if refit is not None:
            pi, x, chi2 = refit
            method = "physically consistent least squares"
            fit["physical_fit"] = {
                "chi2_increase": chi2,
                "base_parameters": x[:n_link].tolist(),
                "rotor_inertia": x[n_link : n_link + n].tolist(),
            }
            instead = (
                "the returned robot takes its links, rotor inertias and friction from the "
                f"least-squares fit constrained to physical links and non-negative rotor "
                f"inertias (chi^2 up by {chi2:.3g}; fit['physical_fit'], while "
                "fit['base_parameters'] and fit['regression'] are the unconstrained fit)"
            )
            for j, p in flagged.items():
                warnings.append(f"link {j + 1} ({robot.joints[j].name}): {p}; {instead}")
            for m in negative:
                warnings.append(
                    f"joint {m + 1} ({robot.joints[m].name}): identified rotor inertia "
                    f"{x_fit[n_link + m]:.3g} kg m^2 is negative; {instead}"
                )
            problems = link_consistency(pi - payload)
    fit["write_back"] = method
    fit["links_not_physical_closest"] = tuple(sorted(j + 1 for j in flagged))
    links = pi - payload
    joints: list[Joint] = []
    for j, joint in enumerate(robot.joints):
        link, problem_j = joint.link, problems[j]
        if problem_j is None:
            mass, c, i_c = link_from_standard(links[10 * j : 10 * j + 10])
            inertia = np.array([i_c[0, 0], i_c[1, 1], i_c[2, 2], i_c[0, 1], i_c[1, 2], i_c[0, 2]])
            try:
                link = Link(mass=mass, com=c, inertia=inertia)
            except KinergyError as err:
                problem_j = str(err)
        if problem_j is not None:
            warnings.append(
                f"link {j + 1} ({joint.name}): {problem_j}; kept the model's mass, centre of mass "
                "and inertia for this link, so the returned robot's torques differ from the "
                "identified base parameters' (fit['regression'] is the identified fit, "
                "fit['torque'], fit['current'] and fit['joint_torque'] the returned robot's)"
            )
            links[10 * j : 10 * j + 10] = inertial_parameters(robot, include_payload=False)[
                10 * j : 10 * j + 10
            ]
        problems[j] = problem_j
        joints.append(dataclasses.replace(joint, link=link))
    fit["links_physical"] = tuple(p is None for p in problems)
    fit["standard_parameters"] = dict(zip(parameter_names(robot), links.tolist(), strict=True))

    final = []
    for m, joint in enumerate(joints):
        drive = joint.drive
        rotor = float(x[n_link + m])
        if rotor < drive.reducer_inertia:
            # motor inertia clipped at 0; the reducer inertia gives way too, so the written
            # J_m + J_r is the identified one (arms with link-side torque sensors see about 0)
            reducer = max(rotor, 0.0)
            warnings.append(
                f"joint {m + 1} ({joint.name}): identified rotor inertia {rotor:.3g} kg m^2 is "
                + ("not positive" if rotor <= 0.0 else "below the model's reducer inertia")
                + f" ({drive.reducer_inertia:.3g}): motor inertia set to 0 and reducer inertia "
                f"to {reducer:.3g} kg m^2"
            )
            drive = dataclasses.replace(drive, motor_inertia=0.0, reducer_inertia=reducer)
        else:
            drive = dataclasses.replace(drive, motor_inertia=rotor - drive.reducer_inertia)
        if not commanded:
            values = x[cols.fric_at[m] : cols.fric_at[m + 1]]
            for name, value in zip(get_model(models[m]).linear, values, strict=True):
                if value < 0.0 and name != "gamma1":
                    warnings.append(
                        f"joint {m + 1} ({joint.name}): friction {name} = {value:.3g} is negative"
                    )
            new = with_linear_parameters(models[m], params[m], values)
            drive = dataclasses.replace(drive, friction=Friction(models[m], new))
        final.append(dataclasses.replace(joint, drive=drive))
    sources: dict[str, Source] = dict(robot.sources)
    kept_links = [str(j + 1) for j, p in enumerate(problems) if p is not None]
    note = (
        f"; link(s) {', '.join(kept_links)} kept from the model (not physical)"
        if kept_links
        else ""
    )
    how = f" ({method})"
    for group in ("mass", "com", "inertia"):
        sources[group] = Source("identified", _REF + how + note)
    sources["drive_inertia"] = Source("identified", _REF)
    if not commanded:
        sources["friction"] = Source("identified", _REF)
    return dataclasses.replace(robot.with_joints(final), sources=sources), x
