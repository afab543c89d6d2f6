"""The drive steps of the sequential identification (UR5e doc sections 3-4), as folds over chunks.

- :func:`rotor_problem`, :func:`rotor_step`: ``J_m + J_r`` per motor from the controller's
  reference torque (UR5e eqs 7-9), by least squares through the transmission matrix, its rows
  folded chunk by chunk into one QR triangle;
- :func:`current_step`: torque constant and friction of every motor together from the measured
  current (UR5e eqs 17-18): the current is linear in ``1/k_t`` (times the load torque) and in the
  friction parameters over ``k_t``. Each fit it tries (a model, its shape, the fraction of its
  friction a stopped joint holds: a *trial*) is a triangle per block of samples, folded in one
  pass over the chunks with currents together with every other trial asked for at the same
  time: the holds of every joint in one pass; a shape search (``power_law``'s exponent,
  :func:`~kinergy.identification.friction_curve.shape_search`) a pass per step of all joints' searches;
  ``friction="auto"`` scores each model by cross-validation over :data:`FOLDS` blocks from
  those per-block triangles (no pass of its own). When more than one pass may be needed, the
  motor signals of eq 18 (load torque, speed, acceleration, current) are kept from the first.

:mod:`kinergy.identification.sequential` runs them in order and assembles the typed result.

One difference from a cross-validation that refits on the rows left: each block's rows carry the
friction their whole log held through standstill into them, also when the block before them is
the one left out (refitting the rows left would start the hold afresh after the gap). Only
stopped rows right after a block edge can differ, and the held friction is the motion's, not the
measured current's.
"""

from __future__ import annotations

import dataclasses
import itertools
from collections.abc import Iterator, Sequence
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from kinergy.arrays import Array
from kinergy.drives.transmission import transmission_matrix
from kinergy.dynamics.rnea import rnea
from kinergy.errors import KinergyError
from kinergy.friction.model import FrictionModel
from kinergy.friction.registry import MODELS
from kinergy.identification.chunks import (
    STILL_SPEED,
    Asks,
    History,
    LogChunks,
    Summary,
    answer,
    together,
    translated,
)
from kinergy.identification.friction_curve import shape_search
from kinergy.identification.options import CurrentOptions, Hold
from kinergy.identification.result import IDENTIFIED, KEPT, Flag
from kinergy.jsonable import OPTIONAL
from kinergy.linalg import Reduced, scaled_solution
from kinergy.logs.prepare import IdentData
from kinergy.messages import Messages
from kinergy.model.robot import Friction, Joint, Robot

__all__ = [
    "AUTO_CANDIDATES",
    "FOLDS",
    "HOLDINGS",
    "JACKKNIFE_BLOCKS",
    "STILL_SPEED",
    "CurrentStats",
    "FrictionChoice",
    "block_edges",
    "candidates",
    "current_step",
    "grouped",
    "holdings_of",
    "joined",
    "motor_signals",
    "per_motor",
    "replicates",
    "rotor_columns",
    "rotor_problem",
    "rotor_solution",
    "rotor_step",
    "signal_history",
    "solve_current",
    "start_params",
    "with_rotor_inertias",
]


#: a regression whose column-scaled condition number exceeds this cannot be trusted
MAX_CONDITION = 1e8
#: fractions of the friction a stopped joint is tried with (0: none, the seed's model)
HOLDINGS = (0.0, 0.25, 0.5, 0.75, 1.0)
#: a holding fraction is kept only if it cuts the squared current error by this share
MIN_GAIN = 0.005
#: relative standard deviation of 1/k_t above which the torque constant counts as unidentified
MAX_KT_SPREAD = 0.1
#: the models ``friction="auto"`` tries (those the logs support, :func:`candidates`)
AUTO_CANDIDATES = tuple(
    MODELS[name]
    for name in (
        "viscous_coulomb",
        "power_flow",
        "power_law",
        "directional_power_law",
        "stribeck",
        "load_coulomb",
        "thermal_viscous",
        "load_thermal_power_law",
    )
)
#: the family ``friction="auto"`` keeps unless another beats it by more than the standard error
BASELINE = MODELS["viscous_coulomb"]
#: temperature-dependent models are tried on a joint whose temperature spans this much, K
MIN_TEMPERATURE_SPAN = 3.0
#: contiguous blocks of the cross-validation that chooses a friction model
FOLDS = 5
#: contiguous time blocks of the jackknife that gives the parameters' errors (without ``auto``)
JACKKNIFE_BLOCKS = 10
#: samples per triangle of step 2 (:func:`rotor_problem`), grouped into the jackknife's blocks
PIECE = 200


def joined(problems: Sequence[Reduced]) -> Reduced:
    """Least-squares problems in the same unknowns (unit column scale, as
    :meth:`Reduced.empty <kinergy.linalg.Reduced.empty>` starts them) together: the triangle of
    their triangles, the rows of all."""
    r = np.vstack([p.r for p in problems])
    both = Reduced.empty(r.shape[1] - 1).stack(r[:, :-1], r[:, -1])
    return dataclasses.replace(both, rows=sum(p.rows for p in problems))


# ---------------------------------------------------------------------------------------------
# Step 2: rotor inertias (UR5e eqs 7-9, Table IV)


def rotor_columns(n_mat: Array, dwm: Array) -> Array:
    """Reflected rotor inertia columns, shape (N, n, n): motor ``m``'s column on joint ``j`` is
    ``N[m, j] (N qdd)_m`` (UR5e eq 2), ``dwm = qdd N^T`` (N, n) the motor accelerations, rad/s^2;
    times ``J`` (kg m^2, motor side) they give joint torques ``N^T diag(J) N qdd``."""
    return n_mat.T[None, :, :] * dwm[:, None, :]


def rotor_problem(robot: Robot, logs: LogChunks) -> list[Reduced] | None:
    """Step 2's least squares (UR5e eqs 7-9) folded into triangles (:class:`Reduced`), every
    motor's column: ``tau_ref - f_link = N^T diag(J) N qdd`` with ``N`` the transmission matrix,
    linear in J; rows (sample, joint) of every chunk with ``target_moment``, one triangle per
    :data:`PIECE` consecutive samples (:func:`joined` gives the whole problem, groups of them
    the jackknife's blocks); None: there is none."""
    n_mat = transmission_matrix(robot)
    pieces: list[Reduced] = []
    for _, chunk in logs.chunks("tau_ref"):
        assert chunk.tau_ref is not None
        f_link = rnea(robot, chunk.q_cmd, chunk.qd_cmd, chunk.qdd_cmd)
        # rows (sample, joint), column m: contribution of J_m, n_mat[m, j] * (N qdd)_m
        a = rotor_columns(n_mat, chunk.qdd_cmd @ n_mat.T)
        y = chunk.tau_ref - f_link
        for lo in range(0, y.shape[0], PIECE):
            rows = slice(lo, lo + PIECE)
            piece = Reduced.empty(robot.n).stack(a[rows].reshape(-1, robot.n), y[rows].reshape(-1))
            pieces.append(piece)
    return pieces or None


def grouped(pieces: Sequence[Reduced], blocks: int) -> list[Reduced]:
    """Consecutive ``pieces`` joined into ``blocks`` groups of about equal rows (fewer when
    there are fewer pieces)."""
    rows = np.cumsum([p.rows for p in pieces])
    cut = np.searchsorted(rows, np.linspace(0, rows[-1], blocks + 1)[1:-1], side="right")
    edges = [0, *sorted(set(cut.tolist()) - {0, len(pieces)}), len(pieces)]
    return [joined(pieces[a:b]) for a, b in itertools.pairwise(edges)]


def rotor_solution(
    robot: Robot, problem: Reduced, active: Sequence[int] | None = None
) -> tuple[Array, Array, float]:
    """Step 2 from its triangle (:func:`rotor_problem`): ``J_m + J_r`` per motor.

    Returns
    -------
    inertia, std : ndarray, shape (n,)
        kg m^2 (motor side) and its standard deviation; motors not in ``active`` (default all)
        keep the model's value (moved into the target) and a NaN deviation.
    condition : float
    """
    active = list(range(robot.n)) if active is None else list(active)
    known = np.array([j.drive.rotor_inertia for j in robot.joints])
    pick = np.zeros((robot.n + 1, len(active) + 1))
    pick[active, np.arange(len(active))] = 1.0
    pick[:, -1] = np.append([0.0 if m in active else -known[m] for m in range(robot.n)], 1.0)
    sol, sol_std, cond = scaled_solution(problem.combine(pick))
    inertia, std = known.copy(), np.full(robot.n, np.nan)
    inertia[active], std[active] = sol, sol_std
    return inertia, std, cond


def rotor_step(
    robot: Robot, problem: Reduced | None, active: list[int], said: Messages
) -> tuple[Array, Array, float | None]:
    """Rotor inertias (kg m^2, motor side) from step 2's triangle (:func:`rotor_problem`; None
    when no log has ``target_moment``), their standard errors (NaN where not identified) and
    the regression's condition number (None without ``target_moment``). A rotor inertia that
    comes out negative is not written: the model's is kept (NaN standard error) with a warning."""
    rotor = np.array([j.drive.rotor_inertia for j in robot.joints])
    rotor_std = np.full(robot.n, np.nan)
    cond = None
    if problem is not None:
        rotor, rotor_std, cond = rotor_solution(robot, problem, active)
        if cond > MAX_CONDITION:
            raise KinergyError(
                f"rotor inertia regression is singular (condition {cond:.3g}): too little acceleration"
            )
    else:
        said.note("the logs have no target_moment: rotor inertias kept from the model")
    for j, joint in enumerate(robot.joints):
        if rotor[j] < 0:
            said.warn(
                f"joint {j + 1} ({joint.name}): identified rotor inertia {rotor[j]:.3g} kg m² "
                "is negative, not a physical value (target_moment does not fit this model): "
                f"kept the model's {joint.drive.rotor_inertia:.4g} kg m²"
            )
            rotor[j], rotor_std[j] = joint.drive.rotor_inertia, np.nan
    return rotor, rotor_std, cond


def with_rotor_inertias(robot: Robot, rotor: Array, said: Messages) -> Robot:
    """Motor inertia = rotor inertia - the model's reducer inertia (Table IV), at least 0."""
    joints = []
    for j, joint in enumerate(robot.joints):
        drive = joint.drive
        motor = max(float(rotor[j]) - drive.reducer_inertia, 0.0)
        joints.append(
            dataclasses.replace(joint, drive=dataclasses.replace(drive, motor_inertia=motor))
        )
    for j, joint in enumerate(robot.joints):
        if rotor[j] < joint.drive.reducer_inertia:
            said.note(
                f"joint {j + 1} ({joint.name}): rotor inertia {rotor[j]:.3g} is below the model's "
                f"reducer inertia {joint.drive.reducer_inertia:.3g}; motor inertia set to 0"
            )
    return robot.with_joints(joints)


# ---------------------------------------------------------------------------------------------
# Step 3: torque constants and friction (UR5e eqs 17-18)


@dataclass(frozen=True, eq=False)
class _Signals:
    """One motor's signals for eq 18, motor side, each (N,): load torque ``tau_load`` (N m),
    speed ``wm`` (rad/s), acceleration ``dwm`` (rad/s^2), measured ``current`` (A), the joint
    ``temperature`` (deg C, None when not logged) and the stretch of time each row belongs to
    (``piece``, int: a friction held through standstill never crosses into the next piece)."""

    tau_load: Array
    wm: Array
    dwm: Array
    current: Array
    temperature: Array | None = None
    piece: NDArray[np.int64] | None = None


def _columns(model: FrictionModel, params: dict[str, float], signals: _Signals) -> Array:
    """Eq 18's regressor ``[tau_load, friction columns]`` (N, 1 + k)."""
    s = signals
    bounds = [0, s.wm.size]
    if s.piece is not None:
        bounds[1:1] = list(np.flatnonzero(np.diff(s.piece)) + 1)
    parts = []
    for lo, hi in itertools.pairwise(bounds):
        t = None if s.temperature is None else s.temperature[lo:hi]
        w, load, dw = s.wm[lo:hi], s.tau_load[lo:hi], s.dwm[lo:hi]
        parts.append(model.friction_columns(params, w, load, dw, temperature=t))
    return np.column_stack([s.tau_load, np.vstack(parts)])


def signal_history(still: float) -> History[_Signals]:
    """A :class:`~kinergy.identification.chunks.History` of one motor's eq 18 signals."""

    def take(x: _Signals, index: NDArray[np.int64]) -> _Signals:
        t = None if x.temperature is None else x.temperature[index]
        return _Signals(x.tau_load[index], x.wm[index], x.dwm[index], x.current[index], t)

    def join(parts: Sequence[_Signals]) -> _Signals:
        def cat(name: str) -> Array | None:
            values = [getattr(p, name) for p in parts]
            return None if any(v is None for v in values) else np.concatenate(values)

        return _Signals(*(cat(n) for n in ("tau_load", "wm", "dwm", "current", "temperature")))  # type: ignore[arg-type]

    def at_rest(x: _Signals) -> _Signals:
        return dataclasses.replace(x, wm=np.zeros_like(x.wm), dwm=np.zeros_like(x.dwm))

    return History([still], take, join, at_rest, lambda x: x.wm[:, None])


def motor_signals(
    robot: Robot, rotor: Array, chunk: IdentData, temperature: bool
) -> list[Array | None]:
    """Eq 18's signals of every motor on the chunk's real motion: the load torque of ``robot``
    with rotor inertias ``rotor`` (N m), the motor speed (rad/s) and acceleration (rad/s^2), the
    measured current (A), each (N, n), and (``temperature``, else None) the joint temperatures
    (deg C); :func:`per_motor` splits them."""
    assert chunk.current is not None
    n_mat = transmission_matrix(robot)
    tau_sim = rnea(robot, chunk.q, chunk.qd, chunk.qdd)
    tau_sim += chunk.qdd @ (n_mat.T @ (rotor[:, None] * n_mat)).T
    tau_load = np.asarray(np.linalg.solve(n_mat.T, tau_sim.T).T, dtype=float)
    temps = chunk.temperature if temperature else None
    return [tau_load, chunk.qd @ n_mat.T, chunk.qdd @ n_mat.T, chunk.current, temps]


def per_motor(signals: Sequence[Array | None]) -> list[_Signals]:
    """:func:`motor_signals` as each motor's :class:`_Signals`."""
    tau_load, wm, dwm, current, temps = signals
    assert tau_load is not None and wm is not None and dwm is not None and current is not None
    return [
        _Signals(
            tau_load[:, m],
            wm[:, m],
            dwm[:, m],
            current[:, m],
            None if temps is None else temps[:, m],
        )
        for m in range(tau_load.shape[1])
    ]


@dataclass(frozen=True, eq=False)
class _CurrentFit:
    """Eq 18 for one motor: ``x = [1/k_t, values/k_t]`` with standard errors, the condition
    number, the squared current error, and whether ``k_t`` was held at the model's."""

    model: FrictionModel
    params: dict[str, float]
    x: Array
    std: Array
    cond: float
    sse: float
    fixed: bool


def solve_current(
    model: FrictionModel, params: dict[str, float], problem: Reduced, kt_prior: float
) -> _CurrentFit:
    """Eq 18 for one motor, ``I = [tau_load, friction columns] @ [1/k_t, values/k_t]``, the
    model's shape parameters held, from its triangle (:class:`Reduced`, unit column scale).

    When the load torque is too small against the friction and noise to pin ``1/k_t`` down
    (relative standard deviation above :data:`MAX_KT_SPREAD`, or a non-positive estimate),
    ``k_t`` is fixed at ``kt_prior`` and only the friction is fitted.
    """
    x, std, cond = scaled_solution(problem)
    fixed = not (x[0] > 0 and std[0] < MAX_KT_SPREAD * x[0])
    if fixed:
        p = problem.r.shape[1] - 1
        rest_of = np.zeros((p + 1, p))  # the friction columns against current - tau_load / k_t
        rest_of[1:p, : p - 1] = np.eye(p - 1)
        rest_of[0, -1], rest_of[p, -1] = -1.0 / kt_prior, 1.0
        rest, rest_std, cond = scaled_solution(problem.combine(rest_of))
        x = np.concatenate([[1.0 / kt_prior], rest])
        std = np.concatenate([[0.0], rest_std])
    return _CurrentFit(model, params, x, std, cond, problem.norm2(np.append(-x, 1.0)), fixed)


def start_params(
    joint: Joint, model: FrictionModel, standstill: float, holding: float
) -> dict[str, float]:
    """Parameters to fit ``model`` from, holding ``holding`` of the friction through standstill."""
    params = model.start(joint.drive.friction.model, joint.drive.friction.params)
    params.pop("standstill", None)
    params.pop("holding", None)
    if holding > 0.0:
        params["standstill"] = standstill
        params["holding"] = holding
    return params


def holdings_of(hold: Hold) -> tuple[float, ...]:
    """The friction fractions held through standstill that ``hold`` tries (:data:`HOLDINGS`)."""
    return {Hold.SEARCH: HOLDINGS, Hold.NONE: (0.0,), Hold.FULL: (1.0,)}[hold]


@dataclass(frozen=True)
class _Trial:
    """One fit of eq 18 tried: a motor, a friction model and all its parameters."""

    motor: int
    model: FrictionModel
    params: tuple[tuple[str, float], ...]

    @classmethod
    def of(cls, motor: int, model: FrictionModel, params: dict[str, float]) -> _Trial:
        return cls(motor, model, tuple(params.items()))


@dataclass(eq=False)
class _Blocks:
    """A trial's eq 18 folded into one triangle per block of samples (:func:`joined` gives the
    whole problem)."""

    parts: list[Reduced]
    _total: Reduced | None = None

    @property
    def total(self) -> Reduced:
        if self._total is None:
            self._total = self.parts[0] if len(self.parts) == 1 else joined(self.parts)
        return self._total


class _Passes:
    """Answers the trials of eq 18 asked for (:data:`~kinergy.identification.chunks.Asks`): each new
    batch is one pass over the logs with currents, the motor signals of ``staged`` with rotor
    inertias ``rotor`` computed on the first and, when ``keep``, kept for the others; every
    trial's triangles are cached. ``edges`` cut the samples (of those logs, stacked) into the
    blocks each trial is folded into."""

    def __init__(
        self, logs: LogChunks, staged: Robot, rotor: Array, edges: Sequence[int], keep: bool
    ):
        self.logs, self.staged, self.rotor, self.edges = logs, staged, rotor, list(edges)
        # one log with currents but no temperatures turns them off for all
        self.warm = all("temperature" in s.has for s in logs.summaries if "current" in s.has)
        self.store = logs.derived() if keep else None
        self.owner: list[int] = []
        self.cache: dict[_Trial, _Blocks] = {}
        self.still = [STILL_SPEED * abs(j.drive.gear_ratio) for j in staged.joints]

    def _signals(self) -> Iterator[tuple[int, list[_Signals]]]:
        if self.store is not None and self.owner:
            for k, record in zip(self.owner, self.store, strict=True):
                yield k, per_motor(record)
            return
        for k, chunk in self.logs.chunks("current"):
            signals = motor_signals(self.staged, self.rotor, chunk, self.warm)
            if self.store is not None:
                self.store.put(signals)
                self.owner.append(k)
            yield k, per_motor(signals)

    def __call__(self, asked: list[_Trial]) -> list[_Blocks]:
        new = list(dict.fromkeys(t for t in asked if t not in self.cache))
        if new:
            self.cache.update(self._fold(new))
        return [self.cache[t] for t in asked]

    def _fold(self, trials: list[_Trial]) -> dict[_Trial, _Blocks]:
        """One pass: every trial's triangles."""
        widths = {t: 1 + len(t.model.linear) for t in trials}
        out = {t: _Blocks([Reduced.empty(widths[t]) for _ in self.edges[1:]]) for t in trials}
        motors = sorted({t.motor for t in trials})
        history = {m: signal_history(self.still[m]) for m in motors}
        at = 0
        for k, signals in self._signals():
            size = signals[0].wm.size
            cuts = [
                (b, max(lo, at) - at, min(hi, at + size) - at)
                for b, (lo, hi) in enumerate(itertools.pairwise(self.edges))
                if lo < at + size and hi > at
            ]
            for m in motors:
                data, skip = history[m].ahead(k, signals[m])
                for t in (t for t in trials if t.motor == m):
                    cols = _columns(t.model, dict(t.params), data)[skip:]
                    parts = out[t].parts
                    for b, lo, hi in cuts:
                        parts[b] = parts[b].stack(cols[lo:hi], signals[m].current[lo:hi])
                history[m].update(data, skip)
            at += size
        return out


def _solved(trial: _Trial, blocks: _Blocks, kt: float) -> _CurrentFit:
    return solve_current(trial.model, dict(trial.params), blocks.total, kt)


def _fit_hold(
    m: int, joint: Joint, model: FrictionModel, params: dict[str, float]
) -> Asks[_Trial, _Blocks, tuple[_CurrentFit, _Blocks]]:
    """Eq 18 for motor ``m`` from ``params``, their shape searched first where the model does
    (:func:`~kinergy.identification.friction_curve.shape_search`, on the squared current error)."""
    kt = joint.drive.torque_constant
    if model.search:
        params = yield from translated(
            shape_search(model, params),
            lambda p: _Trial.of(m, model, p),
            lambda p, b: _solved(_Trial.of(m, model, p), b, kt).sse,
        )
    trial = _Trial.of(m, model, params)
    (blocks,) = yield [trial]
    return _solved(trial, blocks, kt), blocks


def _fit_model(
    m: int, joint: Joint, model: FrictionModel, holdings: Sequence[float]
) -> Asks[_Trial, _Blocks, tuple[_CurrentFit, _Blocks]]:
    """Eq 18 with each fraction of ``holdings`` of the friction held through standstill: the
    first fit whose squared current error no later one cuts by :data:`MIN_GAIN`."""
    standstill = STILL_SPEED * abs(joint.drive.gear_ratio)
    fits = yield from together(
        [_fit_hold(m, joint, model, start_params(joint, model, standstill, h)) for h in holdings]
    )
    best = fits[0]
    for this in fits[1:]:
        if this[0].sse < best[0].sse * (1.0 - MIN_GAIN):
            best = this
    return best


@dataclass(frozen=True)
class FrictionChoice:
    """How ``friction="auto"`` chose a joint's model: each candidate's cross-validated current
    RMS (A, :data:`FOLDS` contiguous blocks), the winner, how much lower its RMS is than
    Coulomb + viscous's and than the runner-up's (%), and the standard error of the first (%,
    from the spread of the per-block differences). A model other than Coulomb + viscous wins
    only if it beats it by more than that standard error (the one-standard-error rule)."""

    model: FrictionModel = field(metadata={"json": lambda m: m.name})
    cv_rms: dict[str, float]
    gain_over_viscous_coulomb: float | None
    margin: float | None
    gain_std: float | None = field(default=None, metadata=OPTIONAL)


def candidates(summary: Summary, m: int) -> list[FrictionModel]:
    """The models of :data:`AUTO_CANDIDATES` motor ``m``'s logs (``summary``) can support:
    temperature-dependent ones only where its temperature spans :data:`MIN_TEMPERATURE_SPAN`."""
    cold, warm = summary.cold, summary.warm
    spans = cold is not None and warm is not None and warm[m] - cold[m] >= MIN_TEMPERATURE_SPAN
    return [c for c in AUTO_CANDIDATES if spans or not c.needs_temperature]


def replicates(fit: _CurrentFit, blocks: _Blocks, kt_prior: float) -> Array | None:
    """Delete-one-block jackknife replicates of eq 18's drive, shape (K, 1 + k): each row the
    torque constant (N m/A) and the friction levels ``fit``'s model (shape and hold held)
    gives without block k (:mod:`kinergy.identification.uncertainty`); a torque constant held
    at the model's stays held. None with fewer than 3 blocks."""
    if len(blocks.parts) < 3:
        return None
    rows = []
    for k in range(len(blocks.parts)):
        train = joined([p for i, p in enumerate(blocks.parts) if i != k])
        x = solve_current(fit.model, fit.params, train, kt_prior).x
        kt = 1.0 / fit.x[0] if fit.fixed else 1.0 / x[0]
        rows.append(np.concatenate([[kt], x[1:] / x[0]]))
    return np.array(rows)


def _cv_errors(fit: _CurrentFit, blocks: _Blocks, kt_prior: float) -> Array:
    """Squared current error (A^2) of each block, ``fit``'s model (its shape and hold held)
    fitted on the others, shape (blocks,)."""
    errors = []
    for k, held in enumerate(blocks.parts):
        train = joined([p for i, p in enumerate(blocks.parts) if i != k])
        x = solve_current(fit.model, fit.params, train, kt_prior).x
        errors.append(held.norm2(np.append(-x, 1.0)))
    return np.array(errors)


def _gain(
    errors: dict[FrictionModel, Array], model: FrictionModel, other: FrictionModel
) -> tuple[float, float]:
    """How much lower ``model``'s cross-validated RMS is than ``other``'s (%), and the standard
    error of that gain from the per-block differences of the squared error (%)."""
    a, b = errors[model], errors[other]
    gain = 100.0 * (1.0 - np.sqrt(a.sum() / b.sum()))
    # gain ~ -(sum a - sum b) / (2 sum b); the blocks' differences give that sum's spread
    std = 50.0 * np.sqrt(a.size) * float(np.std(a - b, ddof=1)) / float(b.sum())
    return float(gain), std


def _auto_fit(
    m: int, joint: Joint, models: list[FrictionModel], holdings: Sequence[float], samples: int
) -> Asks[_Trial, _Blocks, tuple[_CurrentFit, FrictionChoice | None, _Blocks]]:
    """``friction="auto"``: every candidate model fitted with its own standstill hold and scored
    by cross-validation; the lowest held-out RMS wins unless it beats Coulomb + viscous by no
    more than the standard error of that gain. Candidates whose regression is singular on these
    logs are left out."""
    kt = joint.drive.torque_constant
    tried = yield from together([_fit_model(m, joint, model, holdings) for model in models])
    fits: dict[FrictionModel, _CurrentFit] = {}
    errors: dict[FrictionModel, Array] = {}
    for model, (fit, blocks) in zip(models, tried, strict=True):
        if fit.cond <= MAX_CONDITION:
            fits[model], errors[model] = fit, _cv_errors(fit, blocks, kt)
    if not fits:  # every candidate singular: as the first (refused, naming it)
        return tried[0][0], None, tried[0][1]
    scores = {c: float(np.sqrt(e.sum() / samples)) for c, e in errors.items()}
    ranked = sorted(scores, key=scores.__getitem__)
    best, gain, std = ranked[0], None, None
    if BASELINE in scores:
        gain, std = _gain(errors, best, BASELINE)
        if gain <= std:
            best = BASELINE
            gain, std = 0.0, None
    others = [c for c in ranked if c != best]
    choice = FrictionChoice(
        model=best,
        cv_rms={c.name: score for c, score in scores.items()},
        gain_over_viscous_coulomb=gain,
        margin=100.0 * (1.0 - scores[best] / scores[others[0]]) if others else None,
        gain_std=std,
    )
    return fits[best], choice, dict(zip(models, tried, strict=True))[best][1]


def _fixed_fit(
    m: int, joint: Joint, model: FrictionModel, holdings: Sequence[float]
) -> Asks[_Trial, _Blocks, tuple[_CurrentFit, FrictionChoice | None, _Blocks]]:
    fit, blocks = yield from _fit_model(m, joint, model, holdings)
    return fit, None, blocks


@dataclass(frozen=True)
class CurrentStats:
    """A joint's standard errors and condition number from eq 18 (:class:`SequentialJoint`),
    and the flags of its torque constant and friction parameters (empty: not fitted)."""

    torque_constant_std: float | None = None
    friction_std: dict[str, float] | None = None
    condition_current: float | None = None
    flags: dict[str, Flag] = field(default_factory=dict)
    replicates: Array | None = field(default=None, repr=False)


def _unsupported(model: FrictionModel, values: Array, kt: float) -> str | None:
    """Why a current fit's torque constant ``kt`` and friction levels ``values`` are not a
    physical drive (a friction level outside its model's bounds), or None."""
    if not kt > 0:
        return f"torque constant {kt:.3g} N m/A is not positive"
    for name, value in zip(model.linear, values, strict=True):
        low, high = model.bounds.get(name, (-np.inf, np.inf))
        if not low <= value <= high:
            return f"friction {name} = {value:.3g} is outside [{low:.3g}, {high:.3g}]"
    return None


def _apply_current_fit(
    m: int, joint: Joint, fit: _CurrentFit, said: Messages, jackknife: Array | None = None
) -> tuple[Joint, CurrentStats]:
    """``joint`` with the torque constant and friction of ``fit``, and their standard errors;
    a fit that is not a physical drive is not written (the model's values, flagged)."""
    if fit.cond > MAX_CONDITION:
        raise KinergyError(
            f"joint {m + 1} ({joint.name}): the current regression is singular (condition "
            f"{fit.cond:.3g}): the log does not excite every friction term of model {fit.model.name!r}"
        )
    x, std, names = fit.x, fit.std, fit.model.linear
    kt = 1.0 / x[0]
    values = x[1:] * kt
    problem = _unsupported(fit.model, values, kt)
    if problem is not None:
        said.warn(
            f"joint {m + 1} ({joint.name}): {problem}, not a physical drive (the currents do "
            f"not support friction model {fit.model.name!r} here): kept the model's torque constant "
            "and friction"
        )
        kept = {name: KEPT for name in ("torque_constant", *names)}
        return joint, CurrentStats(condition_current=fit.cond, flags=kept)
    if fit.fixed:
        said.note(
            f"joint {m + 1} ({joint.name}): the logs do not pin the torque constant down "
            "(too little load torque against friction and noise); kept the model's "
            f"{joint.drive.torque_constant:.4g} N m/A"
        )
    kt_std = std[0] / x[0] ** 2
    value_std = np.sqrt((std[1:] * kt) ** 2 + (x[1:] * kt_std * kt) ** 2)
    friction = Friction(fit.model, fit.model.with_values(fit.params, values))
    drive = dataclasses.replace(joint.drive, torque_constant=float(kt), friction=friction)
    flags = {"torque_constant": KEPT if fit.fixed else IDENTIFIED}
    flags.update({name: IDENTIFIED for name in names})
    stats = CurrentStats(
        torque_constant_std=float(kt_std),
        friction_std={name: float(s) for name, s in zip(names, value_std, strict=True)},
        condition_current=fit.cond,
        flags=flags,
        replicates=jackknife,
    )
    return dataclasses.replace(joint, drive=drive), stats


def block_edges(logs: LogChunks, folds: bool) -> list[int]:
    """Where the cross-validation's blocks of the samples of the logs with currents (stacked)
    begin and end: each log, when there are 3 or more, else :data:`FOLDS` contiguous blocks;
    without ``auto`` (``folds=False``), :data:`JACKKNIFE_BLOCKS` contiguous blocks."""
    sizes = [logs.summaries[k].samples for k in logs.which("current")]
    if not folds:
        return np.linspace(0, sum(sizes), JACKKNIFE_BLOCKS + 1).astype(int).tolist()
    if len(sizes) >= 3:
        return [0, *np.cumsum(sizes).tolist()]
    return np.linspace(0, sum(sizes), FOLDS + 1).astype(int).tolist()


def current_step(
    staged: Robot,
    rotor: Array,
    logs: LogChunks,
    problems: dict[int, str],
    options: CurrentOptions,
    said: Messages,
) -> tuple[Robot, list[CurrentStats], tuple[float | None, ...], tuple[FrictionChoice | None, ...]]:
    """Torque constants and friction of every identifiable motor from the currents of ``logs``
    (eqs 17-18; the motors in ``problems`` keep the model's), every joint's fits folded in the
    same passes (module docstring). Returns the robot, each joint's statistics, the friction
    fraction held through standstill and, with ``"auto"``, how each joint's model was chosen
    (None where not fitted)."""
    holdings = holdings_of(options.hold)
    active = [m for m in range(staged.n) if m not in problems]
    models = [options.family or j.drive.friction.model for j in staged.joints]
    summary = logs.summary("current")
    edges = block_edges(logs, options.auto)
    several = options.auto or any(models[m].search for m in active)  # passes: keep the signals
    passes = _Passes(logs, staged, rotor, edges, several)
    if options.auto:
        asks = [
            _auto_fit(m, staged.joints[m], candidates(summary, m), holdings, summary.samples)
            for m in active
        ]
    else:
        asks = [_fixed_fit(m, staged.joints[m], models[m], holdings) for m in active]
    fits = dict(zip(active, answer(together(asks), passes), strict=True))
    joints: list[Joint] = []
    stats: list[CurrentStats] = []
    held: list[float | None] = []
    chosen: list[FrictionChoice | None] = []
    for m, joint in enumerate(staged.joints):
        if m not in fits:
            joints.append(joint)
            stats.append(CurrentStats())
            held.append(None)
            chosen.append(None)
            continue
        fit, choice, blocks = fits[m]
        held.append(float(fit.params.get("holding", 0.0)))
        chosen.append(choice)
        jackknife = replicates(fit, blocks, joint.drive.torque_constant) if options.errors else None
        new, stat = _apply_current_fit(m, joint, fit, said, jackknife)
        joints.append(new)
        stats.append(stat)
    return staged.with_joints(joints), stats, tuple(held), tuple(chosen)
