"""Energy-optimal timing of a movej program: per-move speeds and accelerations for a cycle time.

A task is fixed by its waypoints (the path in joint space); what a UR program is free to choose is
how fast each move runs: URScript's ``movej(q, a=..., v=...)`` per move. For a cycle-time budget
``T`` this module finds the per-move ``v_k, a_k`` (and, optionally, how ``T`` is shared among the
moves) that minimise the electrical energy the model predicts (UR5e eq 26, summed over the
motors), within the joints' speed, acceleration, torque and position limits, and verifies every
result by re-simulating the movej at the controller's 500 Hz with
:func:`kinergy.energy.accounting.energy` and :func:`limit_violations`.

Physics: what the timing can and cannot change
----------------------------------------------
Per motor the electrical power is ``tau_m^2 / k_m^2 + (k_b/k_t) wm tau_m`` (UR5e eq 23) with
``tau_m = tau_inertial + tau_gravity + tau_friction`` (motor side). Over one cycle of a movej
program (every move starts and ends at rest):

- *inertial* and *gravity* work is returned to the bus when braking and lowering (signed integrals,
  as the seed; a closed cycle gives back what it stored): close to zero whatever the timing.
- *Coulomb friction* costs ``Tc |wm|``: its energy is ``Tc`` times the motor-side distance, fixed by
  the path, not by the timing (only the direct/reverse power-flow coefficient, UR5e eqs 11-16,
  depends on the sign of the load torque). This is the floor the timing cannot touch.
- *viscous friction* costs ``b wm^2``: for a move of leading-joint travel ``D`` in time ``t`` its
  energy is ``b D^2 / t`` times a shape factor that is 1 for a constant speed and grows with the
  share of the move spent accelerating (``v^2 (t - 4 tau/3)`` for a trapezoid with ramp ``tau``).
  So at a fixed cycle time it pays to accelerate *harder* (a flatter speed profile, a lower peak
  speed) and to give more of the budget to the moves whose joints travel far on high-viscosity
  drives (equal marginal energy per second of every move: the Lagrange condition of
  ``sum_k E_k(t_k)`` subject to ``sum_k t_k = T``).
- *copper losses* ``tau_m^2 / k_m^2``: the acceleration torque costs about ``J^2 a^2`` over the
  ramps ``2 v / a``, i.e. ``~ 2 J^2 a v`` per move, growing with the acceleration; the gravity
  holding torque costs ``~ tau_g^2 / k_m^2`` per second, growing with the cycle time.

So the optimum is not "as slow as possible" nor "as hard as possible": at a fixed cycle time the
accelerations settle where the viscous saving of a flatter profile meets the extra copper loss of
the ramps (unless a cap or a torque limit binds first), and along the Pareto front (energy against
cycle time) the viscous energy falls like ``1 / T`` while gravity copper grows like ``T``: on the
UR5e the viscous term dominates for cycle times around the programs' own, so the front falls
over the range kinergy scans (fastest feasible to twice the program's time).

What this gives on the seed UR5e model, test A at its own 13.1 s (3 rad/s, 6 rad/s^2): of
1015 J, friction is 959 J (Coulomb 407 J, viscous 552 J) and copper 56 J; the optimum (about
8 %) comes from the viscous part, which even a rectangular speed profile with the best budget
shares could only bring to about 454 J: the Coulomb floor and the budget bound the saving.

Solver and parametrisation
--------------------------
Decision variables (:func:`solve_timing`) are, per move, its duration ``t_k`` (its share of the
budget) and ``ln a_k``; the speed follows as the smaller root of ``t = D / v + v / a``. The
acceleration cap is then a bound (the cap, or where the model has none, the torque-limited
acceleration at full speed, :attr:`TimingProblem.a_fast`), the cycle time is linear
(``sum t_k``; blends: kinergy's overlap rule), and the speed cap and "reaches a speed at all"
(``a t^2 >= 4 D``, a triangle at equality) are smooth inequalities. Unlike ``(v, a)`` this has
no kink at the trapezoid/triangle switch and no curved equality to crawl along. The torque
limits are constraints on the simulated motion (each move's largest ``|tau_joint| / limit``).
:func:`scipy.optimize.minimize` (SLSQP) solves it with forward-difference gradients, all
perturbed programs evaluated in one batched call of the drive model.

Inside the optimiser the energy is a quadrature, not a fixed-step sum: Gauss-Legendre nodes on
every piece between the profiles' switching times (start, end of ramp, start of braking, end),
so the energy is a smooth function of the decision variables (a fixed ``dt`` grid makes it a
staircase in them, which stalls gradient methods) at a few hundred model evaluations per
program. Every result is then re-simulated at 500 Hz (``dt = 0.002``): the energy reported is
that re-simulation's (the quadrature agrees within about 0.1 %), and the limits are checked at
every one of its samples. Should a sample exceed a limit the quadrature nodes missed, the caps
are tightened by the excess and the problem solved again.
"""

from __future__ import annotations

import functools
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any, TypeVar

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.integrate import cumulative_trapezoid
from scipy.optimize import minimize

from kinergy.drives.transmission import joint_torque
from kinergy.dynamics.threads import kernel_threads
from kinergy.energy.accounting import energy
from kinergy.errors import KinergyError
from kinergy.model.robot import Robot
from kinergy.predict import DriveState, drive_state
from kinergy.trajectory.motion import Motion
from kinergy.trajectory.movej import movej, plan_movej

__all__ = [
    "VERIFY_DT",
    "LimitCheck",
    "ParetoPoint",
    "ProgramResult",
    "Solution",
    "TimingProblem",
    "TimingResult",
    "limit_violations",
    "optimize_timing",
    "pareto_front",
    "program_energy",
    "program_settings",
    "simulate_program",
    "solve_timing",
    "timing_problem",
    "uniform_scaling",
]

Array = NDArray[np.float64]

#: sample period of every verification: the UR controller's 500 Hz
VERIFY_DT = 0.002
#: a sample is within a limit when ``|x| / limit <= 1 + LIMIT_TOL``
LIMIT_TOL = 1e-9
#: Gauss-Legendre quadrature: sub-intervals per piece and nodes per sub-interval
_SUB = 4
_ORDER = 4
#: relative forward-difference step in the decision variables
_FD_STEP = 1e-6


_F = TypeVar("_F", bound=Callable[..., Any])


def _serial(func: _F) -> _F:
    """Decorate a public entry point: its dynamics run on the calling thread only
    (:func:`kinergy.dynamics.threads.kernel_threads`)."""

    @functools.wraps(func)
    def wrapper(*args: Any, **kwargs: Any) -> Any:
        with kernel_threads(1):
            return func(*args, **kwargs)

    return wrapper  # type: ignore[return-value]


# -- limits ---------------------------------------------------------------------------------------


@dataclass(frozen=True, eq=False)
class LimitCheck:
    """How close a motion comes to each limit, per sample and joint.

    Every ratio is ``|value| / limit``: a sample is within the limit when the ratio is at most
    ``1 + LIMIT_TOL``. Position ratios are the distance from the middle of the joint range over
    its half width.

    Attributes
    ----------
    joints : list of str
    t : ndarray, shape (N,)
        s.
    ratios : dict of str to ndarray, shape (N, n)
        ``position``, ``speed``, ``acceleration`` (NaN for joints without a limit or cap),
        ``torque`` (joint torque ``N^T tau_m``: what the joint's gearbox carries).
    """

    joints: list[str]
    t: Array
    ratios: dict[str, Array]

    def worst(self) -> dict[str, tuple[float, str, float]]:
        """Per kind: the largest ratio, the joint and the time (s) where it occurs."""
        out: dict[str, tuple[float, str, float]] = {}
        for kind, r in self.ratios.items():
            if r.size == 0 or np.all(np.isnan(r)):
                continue
            flat = int(np.nanargmax(r))
            i, j = np.unravel_index(flat, r.shape)
            out[kind] = (float(r[i, j]), self.joints[int(j)], float(self.t[int(i)]))
        return out

    @property
    def ok(self) -> bool:
        """Whether every sample is within every limit."""
        return all(ratio <= 1.0 + LIMIT_TOL for ratio, _, _ in self.worst().values())

    def violations(self) -> list[str]:
        """One line per exceeded kind of limit (the worst sample), empty when :attr:`ok`."""
        out = []
        for kind, (ratio, joint, t) in self.worst().items():
            if ratio > 1.0 + LIMIT_TOL:
                count = int(np.sum(np.nan_to_num(self.ratios[kind]) > 1.0 + LIMIT_TOL))
                out.append(
                    f"{kind} of {joint} at {ratio:.3f} x its limit at t = {t:.3f} s "
                    f"({count} sample(s) over)"
                )
        return out


def limit_violations(
    robot: Robot,
    motion: Motion,
    state: DriveState,
    *,
    speed_cap: float | None = None,
    acceleration_cap: float | None = None,
) -> LimitCheck:
    """Check a motion against the robot's joint limits (and optional caps) at every sample.

    Parameters
    ----------
    robot : Robot
        Joint ``limits``: position, speed, torque and (where the model has one) acceleration.
    motion : Motion
        Joint angles, speeds, accelerations, shape (N, n).
    state : DriveState
        The drive model over ``motion`` (:func:`kinergy.drives.electrics.drive_state`); the joint
        torque is the motor torque reflected to the joint, ``N^T tau_m``
        (:func:`kinergy.drives.transmission.joint_torque`), friction included.
    speed_cap, acceleration_cap : float, optional
        Extra caps on every joint's ``|qd|`` (rad/s) and ``|qdd|`` (rad/s^2), e.g. an optimiser's
        own: for a movej they bound the leading joint, whose ``v`` and ``a`` URScript sets.

    Returns
    -------
    LimitCheck
    """
    limits = [j.limits for j in robot.joints]
    lo = np.array([lim.position[0] for lim in limits])
    hi = np.array([lim.position[1] for lim in limits])
    speed = np.array([lim.speed for lim in limits])
    if speed_cap is not None:
        speed = np.minimum(speed, speed_cap)
    acc = np.array([np.inf if lim.acceleration is None else lim.acceleration for lim in limits])
    if acceleration_cap is not None:
        acc = np.minimum(acc, acceleration_cap)
    torque = np.array([lim.torque for lim in limits])
    with np.errstate(invalid="ignore", divide="ignore"):
        acc_ratio = np.where(np.isfinite(acc), np.abs(motion.qdd) / acc, np.nan)
    return LimitCheck(
        joints=robot.joint_names,
        t=motion.t,
        ratios={
            "position": np.abs(motion.q - 0.5 * (lo + hi)) / (0.5 * (hi - lo)),
            "speed": np.abs(motion.qd) / speed,
            "acceleration": acc_ratio,
            "torque": np.abs(joint_torque(robot, state.tau_m)) / torque,
        },
    )


# -- re-simulation --------------------------------------------------------------------------------


@_serial
def program_energy(
    robot: Robot,
    waypoints: ArrayLike,
    speeds: ArrayLike,
    accels: ArrayLike,
    blends: ArrayLike = 0.0,
    dt: float = VERIFY_DT,
    *,
    recovery: bool = True,
) -> float:
    """Total electrical energy of a movej program, re-simulated every ``dt`` s, J (UR5e eq 26).

    Parameters
    ----------
    robot : Robot
    waypoints : array_like, shape (K + 1, n)
        Start pose and targets, rad.
    speeds, accels : float or array_like, shape (K,)
        Leading-joint ``v`` (rad/s) and ``a`` (rad/s^2) per move.
    blends : float or array_like, shape (K,)
        Joint-space blend radii, rad (:func:`kinergy.trajectory.movej.plan_movej`).
    dt : float
        Sample period, s (0.002: the controller's 500 Hz).
    recovery : bool
        Braking energy returns to the bus (default, as the seed).
    """
    motion = movej(waypoints, speed=speeds, acceleration=accels, blend=blends, dt=dt)
    return energy(robot, motion, recovery=recovery).total_e_elec


@dataclass(frozen=True, eq=False)
class ProgramResult:
    """A movej program's settings and its re-simulated energy and limits.

    Attributes
    ----------
    label : str
        ``program``, ``uniform`` or ``optimized``.
    speeds, accels, blends : ndarray, shape (K,)
        rad/s, rad/s^2, rad (joint-space blend).
    starts, durations : ndarray, shape (K,)
        When each move starts and how long it lasts on its own, s.
    cycle_time : float
        s.
    e_elec : float
        Total electrical energy of the motors, re-simulated at 500 Hz, J.
    e_moves : ndarray, shape (K,)
        Its share per move (the bus energy between one move's start and the next's), J.
    breakdown : dict of str to float
        ``inertial``, ``gravity``, ``friction``, ``copper`` parts of ``e_elec``, J.
    check : LimitCheck
        The limits at every 500 Hz sample.
    predicted : float or None
        The optimiser's own (quadrature) estimate of ``e_elec``, J.
    """

    label: str
    speeds: Array
    accels: Array
    blends: Array
    starts: Array
    durations: Array
    cycle_time: float
    e_elec: float
    e_moves: Array
    breakdown: dict[str, float]
    check: LimitCheck = field(repr=False)
    predicted: float | None = None

    @property
    def ok(self) -> bool:
        """Whether every 500 Hz sample is within every limit."""
        return self.check.ok

    def to_dict(self) -> dict[str, Any]:
        worst = self.check.worst()
        return {
            "label": self.label,
            "cycle_time": self.cycle_time,
            "e_elec": self.e_elec,
            "predicted_e_elec": self.predicted,
            "breakdown": dict(self.breakdown),
            "moves": [
                {
                    "v": float(self.speeds[k]),
                    "a": float(self.accels[k]),
                    "blend": float(self.blends[k]),
                    "start": float(self.starts[k]),
                    "duration": float(self.durations[k]),
                    "e_elec": float(self.e_moves[k]),
                }
                for k in range(self.speeds.size)
            ],
            "limits": {
                kind: {"ratio": ratio, "joint": joint, "t": t}
                for kind, (ratio, joint, t) in worst.items()
            },
            "within_limits": self.ok,
            "violations": self.check.violations(),
        }


@_serial
def simulate_program(
    robot: Robot,
    waypoints: ArrayLike,
    speeds: ArrayLike,
    accels: ArrayLike,
    blends: ArrayLike = 0.0,
    *,
    dt: float = VERIFY_DT,
    recovery: bool = True,
    speed_cap: float | None = None,
    acceleration_cap: float | None = None,
    label: str = "program",
    predicted: float | None = None,
) -> ProgramResult:
    """Re-simulate a movej program at ``dt``: its energy (total, per move, breakdown) and limits.

    Parameters are those of :func:`program_energy` and :func:`limit_violations`.
    """
    w = np.asarray(waypoints, dtype=float)
    plan = plan_movej(w, speed=speeds, acceleration=accels, blend=blends)
    motion = movej(w, speed=speeds, acceleration=accels, blend=blends, dt=dt)
    report = energy(robot, motion, recovery=recovery)
    bus = report.p_elec.sum(axis=1)
    if not recovery:
        bus = np.maximum(bus, 0.0)
    cumulative = cumulative_trapezoid(bus, motion.t, initial=0.0)
    bounds = np.concatenate([[motion.t[0]], plan.start[1:], [motion.t[-1]]])
    e_moves = np.diff(np.interp(bounds, motion.t, cumulative))
    check = limit_violations(
        robot, motion, report.drive, speed_cap=speed_cap, acceleration_cap=acceleration_cap
    )
    moves = plan.start.size
    return ProgramResult(
        label=label,
        speeds=np.broadcast_to(np.asarray(speeds, dtype=float), (moves,)).copy(),
        accels=np.broadcast_to(np.asarray(accels, dtype=float), (moves,)).copy(),
        blends=np.broadcast_to(np.asarray(blends, dtype=float), (moves,)).copy(),
        starts=plan.start,
        durations=plan.duration,
        cycle_time=plan.total_time,
        e_elec=report.total_e_elec,
        e_moves=e_moves,
        breakdown={k: float(v.sum()) for k, v in report.breakdown.items()},
        check=check,
        predicted=predicted,
    )


def uniform_scaling(speeds: ArrayLike, accels: ArrayLike, factor: float) -> tuple[Array, Array]:
    """Speeds times ``factor`` and accelerations times ``factor^2``: the same movej program run
    ``factor`` times faster (every duration, ramp and blend overlap divided by ``factor``)."""
    return np.asarray(speeds, dtype=float) * factor, np.asarray(accels, dtype=float) * factor**2


# -- the problem as arrays and callables ----------------------------------------------------------


def _settings(travel: Array, t: Array, f: Array) -> tuple[Array, Array, Array]:
    """Peak speed, acceleration and ramp time of trapezoids of travel ``D``, duration ``t`` and
    ramp fraction ``f`` (broadcast), with ``v = D / (t - tau)``, ``a = v / tau``, ``tau = f t / 2``.
    Moves of zero travel get ``v = a = 0``."""
    ramp = 0.5 * f * t
    with np.errstate(divide="ignore", invalid="ignore"):
        v = np.where(travel > 0.0, travel / (t - ramp), 0.0)
        a = np.where(travel > 0.0, v / ramp, 0.0)
    return v, a, ramp


def _from_va(travel: Array, v: Array, a: Array) -> tuple[Array, Array]:
    """Duration and ramp fraction of movej moves at speed ``v`` and acceleration ``a`` (the
    inverse of :func:`_settings`; a triangle when ``D < v^2 / a``)."""
    with np.errstate(divide="ignore", invalid="ignore"):
        triangle = travel < v**2 / a
        peak = np.where(triangle, np.sqrt(a * travel), v)
        ramp = peak / a
        t = np.where(triangle, 2.0 * ramp, travel / v + v / a)
        t = np.where(travel > 0.0, t, 0.0)
        f = np.where(t > 0.0, 2.0 * ramp / t, 1.0)
    return t, f


def _starts(travel: Array, blends: Array, t: Array, a: Array, ramp: Array) -> Array:
    """Start times of the moves, shape like ``t`` (B, K): kinergy's movej blending rule."""
    start = np.zeros_like(t)
    for k in range(1, t.shape[-1]):
        overlap = np.zeros(t.shape[:-1])
        if blends[k - 1] > 0.0 and travel[k - 1] > 0.0 and travel[k] > 0.0:
            overlap = np.minimum(
                np.minimum(np.sqrt(2.0 * blends[k - 1] / a[..., k - 1]), ramp[..., k - 1]),
                ramp[..., k],
            )
        start[..., k] = start[..., k - 1] + t[..., k - 1] - overlap
    return start


def _profile(
    tau: Array, duration: Array, ramp: Array, peak: Array, acc: Array
) -> tuple[Array, Array, Array]:
    """Vectorised trapezoid (as :mod:`kinergy.trajectory.movej`): distance, speed, acceleration
    at local times ``tau``, shape (B, M), for per-row profile parameters, shape (B, 1)."""
    tau = np.clip(tau, 0.0, duration)
    up = tau < ramp
    down = tau > duration - ramp
    rest = duration - tau
    s = np.where(
        up,
        0.5 * acc * tau**2,
        np.where(
            down,
            peak * (duration - ramp) - 0.5 * acc * rest**2,
            0.5 * acc * ramp**2 + peak * (tau - ramp),
        ),
    )
    sd = np.where(up, acc * tau, np.where(down, acc * rest, peak))
    sdd = np.where(up, acc, np.where(down, -acc, 0.0))
    sdd = np.where((tau <= 0.0) | (tau >= duration), 0.0, sdd)
    return s, sd, sdd


_GAUSS_X, _GAUSS_W = np.polynomial.legendre.leggauss(_ORDER)


def _nodes(breaks: Array) -> tuple[Array, Array, NDArray[np.bool_]]:
    """Quadrature nodes and weights over the sorted breakpoints of each row, plus the ends of
    every piece nudged inside it (weight 0, for the limit checks at the switching times).

    ``breaks`` (B, P) sorted; returns times, weights and whether the node lies in a piece of
    non-zero width (B, M): a node of an empty piece sits on a switching time, where rounding
    can put it in two phases at once (the braking of one move and the start of the next)."""
    lo, hi = breaks[:, :-1], breaks[:, 1:]  # (B, P - 1)
    width = (hi - lo) / _SUB
    sub = np.arange(_SUB)
    centre = lo[..., None] + (sub + 0.5) * width[..., None]  # (B, P-1, SUB)
    half = 0.5 * width[..., None, None]
    t = centre[..., None] + half * _GAUSS_X  # (B, P-1, SUB, ORDER)
    w = np.broadcast_to(half * _GAUSS_W, t.shape)
    eps = 1e-9 * np.maximum(hi - lo, 0.0)
    ends = np.stack([lo + eps, hi - eps], axis=-1)  # (B, P-1, 2)
    big_b = breaks.shape[0]
    times = np.concatenate([t.reshape(big_b, -1), ends.reshape(big_b, -1)], axis=1)
    weights = np.concatenate([w.reshape(big_b, -1), np.zeros((big_b, ends[0].size))], axis=1)
    wide = (hi - lo) > 1e-9
    valid = np.concatenate(
        [
            np.broadcast_to(wide[..., None, None], t.shape).reshape(big_b, -1),
            np.broadcast_to(wide[..., None], ends.shape).reshape(big_b, -1),
        ],
        axis=1,
    )
    return times, weights, valid


#: ``(t, f) -> (energy, torque_ratio)`` of B programs, see :class:`TimingProblem`
Evaluator = Callable[[Array, Array], tuple[Array, Array]]
#: ``(t, f) -> cycle time`` of B programs, s
CycleTime = Callable[[Array, Array], Array]


@dataclass(frozen=True, eq=False)
class TimingProblem:
    """A movej timing problem as arrays and callables (build it with :func:`timing_problem`).

    Attributes
    ----------
    waypoints : ndarray, shape (K + 1, n)
        rad.
    travel : ndarray, shape (K,)
        Leading-joint travel of each move, rad.
    blends : ndarray, shape (K,)
        Joint-space blend radii, rad.
    v_cap, a_cap : ndarray, shape (K,)
        Largest leading-joint speed (rad/s) and acceleration (rad/s^2) of each move that keeps
        every joint within its speed and acceleration limits and the caps (``inf``: none).
    a_fast : ndarray, shape (K,)
        The largest acceleration at ``v_cap`` that keeps the torques within limits (and at most
        ``a_cap``): each move's fastest feasible setting.
    evaluate : callable
        ``evaluate(t, f) -> (energy, torque_ratio)``: for B programs given by the durations and
        ramp fractions of their moves, ``t, f`` of shape (B, K), the electrical energy (B,), J,
        and each move's largest joint torque over its limit (B, K).
    cycle : callable
        ``cycle(t, f) -> total time`` (B,), s.
    """

    waypoints: Array
    travel: Array
    blends: Array
    v_cap: Array
    a_cap: Array
    a_fast: Array
    evaluate: Evaluator = field(repr=False)
    cycle: CycleTime = field(repr=False)

    @property
    def moves(self) -> int:
        return int(self.travel.size)

    @property
    def fastest(self) -> tuple[Array, Array]:
        """Durations and ramp fractions of every move at its fastest feasible setting."""
        v = np.where(self.travel > 0.0, self.v_cap, 1.0)
        a = np.where(self.travel > 0.0, self.a_fast, 1.0)
        return _from_va(self.travel, v, a)

    @property
    def fastest_cycle_time(self) -> float:
        """The shortest cycle time within every limit, s."""
        t, f = self.fastest
        return float(self.cycle(t[None, :], f[None, :])[0])


def _evaluator(
    robot: Robot, waypoints: Array, blends: Array, recovery: bool
) -> tuple[Evaluator, CycleTime]:
    """The batched energy/torque evaluator and the cycle-time function of a movej program."""
    delta = np.diff(waypoints, axis=0)
    travel = np.max(np.abs(delta), axis=1)
    with np.errstate(divide="ignore", invalid="ignore"):
        unit = np.where(travel[:, None] > 0.0, delta / travel[:, None], 0.0)  # (K, n)
    torque_limit = np.array([j.limits.torque for j in robot.joints])
    moves, n = unit.shape

    def timing(t: Array, f: Array) -> tuple[Array, Array, Array, Array]:
        v, a, ramp = _settings(travel, t, f)
        start = _starts(travel, blends, t, a, ramp)
        return v, a, ramp, start

    def cycle(t: Array, f: Array) -> Array:
        t = np.atleast_2d(t)
        _, _, _, start = timing(t, np.atleast_2d(f))
        return np.asarray(np.max(start + t, axis=1))

    def evaluate(t: Array, f: Array) -> tuple[Array, Array]:
        t = np.atleast_2d(np.asarray(t, dtype=float))
        f = np.atleast_2d(np.asarray(f, dtype=float))
        v, a, ramp, start = timing(t, f)
        end = start + t
        breaks = np.sort(
            np.concatenate([start, start + ramp, end - ramp, end], axis=1), axis=1
        )  # (B, 4K)
        times, weights, valid = _nodes(breaks)  # (B, M)
        q = np.broadcast_to(waypoints[0], (*times.shape, n)).copy()
        qd = np.zeros_like(q)
        qdd = np.zeros_like(q)
        for k in range(moves):
            if travel[k] == 0.0:
                continue
            s, sd, sdd = _profile(
                times - start[:, k : k + 1],
                t[:, k : k + 1],
                ramp[:, k : k + 1],
                v[:, k : k + 1],
                a[:, k : k + 1],
            )
            q += s[..., None] * unit[k]
            qd += sd[..., None] * unit[k]
            qdd += sdd[..., None] * unit[k]
        state = drive_state(robot, q.reshape(-1, n), qd.reshape(-1, n), qdd.reshape(-1, n))
        bus = state.power.sum(axis=1).reshape(times.shape)
        if not recovery:
            bus = np.maximum(bus, 0.0)
        e = np.sum(weights * bus, axis=1)
        tau = np.abs(joint_torque(robot, state.tau_m)) / torque_limit
        worst = tau.max(axis=1).reshape(times.shape)  # (B, M)
        inside = (
            valid[:, :, None]
            & (times[:, :, None] >= start[:, None, :])
            & (times[:, :, None] <= end[:, None, :])
        )
        ratio = np.max(np.where(inside, worst[:, :, None], 0.0), axis=1)  # (B, K)
        return e, ratio

    return evaluate, cycle


def _caps(
    robot: Robot, waypoints: Array, v_max: float | None, a_max: float | None
) -> tuple[Array, Array, list[str], list[str]]:
    """Per move the largest leading-joint speed and acceleration within every joint's limits and
    the caps, and what sets each (for the report)."""
    delta = np.abs(np.diff(waypoints, axis=0))
    travel = delta.max(axis=1)
    with np.errstate(divide="ignore", invalid="ignore"):
        share = np.where(travel[:, None] > 0.0, delta / travel[:, None], 0.0)  # (K, n)
        speed = np.array([j.limits.speed for j in robot.joints])
        acc = np.array(
            [
                np.inf if j.limits.acceleration is None else j.limits.acceleration
                for j in robot.joints
            ]
        )
        v_joint = np.where(share > 0.0, speed / share, np.inf)
        a_joint = np.where(share > 0.0, acc / share, np.inf)
    names = robot.joint_names
    v_cap, a_cap, v_why, a_why = [], [], [], []
    for k in range(travel.size):
        jv, ja = int(np.argmin(v_joint[k])), int(np.argmin(a_joint[k]))
        v, a = float(v_joint[k, jv]), float(a_joint[k, ja])
        vw, aw = f"{names[jv]} speed limit", f"{names[ja]} acceleration limit"
        if v_max is not None and v_max <= v:
            v, vw = float(v_max), "v_max"
        if a_max is not None and a_max <= a:
            a, aw = float(a_max), "a_max"
        v_cap.append(v)
        a_cap.append(a)
        v_why.append(vw)
        a_why.append(aw if np.isfinite(a) else "torque limits")
    return np.array(v_cap), np.array(a_cap), v_why, a_why


def _fastest_acceleration(evaluate: Evaluator, travel: Array, v_cap: Array, a_cap: Array) -> Array:
    """Per move the largest acceleration (at most ``a_cap``) at ``v_cap`` whose torques stay
    within the limits (0.1 % margin): a geometric scan of every move at once, then a finer linear
    scan inside the bracket each move found."""
    moving = travel > 0.0
    safe = 1.0 - 1e-3
    v = np.where(moving, v_cap, 1.0)

    def feasible(a: Array) -> NDArray[np.bool_]:
        """(G, K) accelerations -> whether each move's torques stay within the limits."""
        a = np.where(moving, np.minimum(a, a_cap), 1.0)
        _, ratio = evaluate(*_from_va(travel, np.broadcast_to(v, a.shape), a))
        return np.asarray(ratio <= safe)

    def last_good(grid: Array, ok: NDArray[np.bool_]) -> Array:
        """Index per move of the last feasible value before the first infeasible (-1: none)."""
        first_bad = np.where(ok.all(axis=0), grid.shape[0], np.argmin(ok, axis=0))
        return np.asarray(first_bad - 1)

    coarse = np.geomspace(0.02, 5000.0, 48)[:, None] * np.ones(travel.size)
    idx = last_good(coarse, feasible(coarse))
    for k in np.flatnonzero(moving & (idx < 0)):
        raise KinergyError(
            f"move {k + 1}: the joint torques exceed their limits even at "
            f"{coarse[0, k]:g} rad/s^2 (a static overload: the payload or the pose)"
        )
    cols = np.arange(travel.size)
    best = coarse[np.maximum(idx, 0), cols]
    above = coarse[np.minimum(idx + 1, coarse.shape[0] - 1), cols]
    fine = best + np.linspace(0.0, 1.0, 33)[1:, None] * (above - best)
    idx = last_good(fine, feasible(fine))
    best = np.where(idx >= 0, fine[np.maximum(idx, 0), cols], best)
    return np.where(moving, np.minimum(best, a_cap), 0.0)


@_serial
def timing_problem(
    robot: Robot,
    waypoints: ArrayLike,
    *,
    blends: ArrayLike | None = None,
    v_max: float | None = None,
    a_max: float | None = None,
    recovery: bool = True,
) -> TimingProblem:
    """Build the timing problem of a movej program through ``waypoints`` on ``robot``.

    Parameters
    ----------
    robot : Robot
    waypoints : array_like, shape (K + 1, n)
        Start pose and the K targets, rad; each within the joints' position limits.
    blends : float or array_like, shape (K,), optional
        Joint-space blend radii, rad (default 0: every move stops at its target).
    v_max, a_max : float, optional
        Caps on the leading joint's speed (rad/s) and acceleration (rad/s^2) besides the joint
        limits; without ``a_max`` a robot without acceleration limits (UR arms) is bounded by its
        torque limits alone.
    recovery : bool
        Braking energy returns to the bus (default, as the seed).

    Returns
    -------
    TimingProblem
    """
    w = np.asarray(waypoints, dtype=float)
    if w.ndim != 2 or w.shape[0] < 2:
        raise KinergyError(f"waypoints: expected shape (K + 1, n) with K >= 1, got {w.shape}")
    if w.shape[1] != robot.n:
        raise KinergyError(f"waypoints have {w.shape[1]} joints but {robot.name} has {robot.n}")
    if not np.all(np.isfinite(w)):
        raise KinergyError("waypoints: not finite")
    for name, cap in (("v_max", v_max), ("a_max", a_max)):
        if cap is not None and not (np.isfinite(cap) and cap > 0.0):
            raise KinergyError(f"{name}: must be > 0, got {cap}")
    for j, joint in enumerate(robot.joints):
        lo, hi = joint.limits.position
        bad = np.flatnonzero((w[:, j] < lo) | (w[:, j] > hi))
        if bad.size:
            i = int(bad[0])
            raise KinergyError(
                f"waypoint {i} ({'start' if i == 0 else f'move {i}'}): {joint.name} at "
                f"{w[i, j]:.4g} rad is outside its limits [{lo:.4g}, {hi:.4g}] rad"
            )
    moves = w.shape[0] - 1
    r = np.zeros(moves) if blends is None else np.asarray(blends, dtype=float)
    r = np.broadcast_to(r, (moves,)).copy() if r.ndim == 0 else r
    if r.shape != (moves,) or np.any(r < 0.0) or not np.all(np.isfinite(r)):
        raise KinergyError(f"blends: expected {moves} finite values >= 0, got {np.shape(r)}")
    travel = np.max(np.abs(np.diff(w, axis=0)), axis=1)
    if not np.any(travel > 0.0):
        raise KinergyError("the task does not move: every target equals the start pose")
    v_cap, a_cap, _, _ = _caps(robot, w, v_max, a_max)
    evaluate, cycle = _evaluator(robot, w, r, recovery)
    a_fast = _fastest_acceleration(evaluate, travel, v_cap, a_cap)
    return TimingProblem(
        waypoints=w,
        travel=travel,
        blends=r,
        v_cap=v_cap,
        a_cap=a_cap,
        a_fast=a_fast,
        evaluate=evaluate,
        cycle=cycle,
    )


# -- the solver -----------------------------------------------------------------------------------


@dataclass(frozen=True)
class Solution:
    """What :func:`solve_timing` found: ``v`` and ``a`` per move (K,), rad/s and rad/s^2, the
    predicted (quadrature) energy, J, and the solver's report."""

    v: Array
    a: Array
    energy: float
    iterations: int
    success: bool
    message: str


def solve_timing(
    problem: TimingProblem,
    cycle_time: float,
    *,
    v0: ArrayLike,
    a0: ArrayLike,
    share_budget: bool = True,
    torque_margin: float = 0.0,
    maxiter: int = 150,
) -> Solution:
    """Minimise the energy of ``problem`` at ``cycle_time`` with SLSQP, starting from ``(v0, a0)``.

    Variables: per move its duration ``t_k`` (its share of the budget) and ``ln a_k``. The
    acceleration cap (``a_fast``: the cap, or the torque-limited acceleration at full speed) is
    then a bound, the cycle time (``sum t_k`` without blends) is linear, and the rest are smooth
    inequalities: the move reaches a speed in its time (``a t^2 >= 4 D``; equality: a triangle),
    and that speed, the smaller root of ``t = D / v + v / a``, is within the speed cap. The torque
    limits are inequalities on each move's largest ``|tau_joint| / limit`` at the quadrature
    nodes. (Parametrising the ramp between the two caps instead makes both caps bounds, but
    degenerates where they meet: a move at its fastest then cannot leave it.)

    Parameters
    ----------
    problem : TimingProblem
    cycle_time : float
        s; the program's total time must equal it.
    v0, a0 : array_like, shape (K,)
        Start (rad/s, rad/s^2): e.g. the program uniformly scaled to the budget.
    share_budget : bool
        Choose each move's share of the budget (default); otherwise every move keeps its share of
        ``(v0, a0)``'s time (one common scale).
    torque_margin : float
        Keep each move's largest joint torque below ``1 - torque_margin`` times its limit.
    maxiter : int
        SLSQP iterations.
    """
    travel = problem.travel
    moving = np.flatnonzero(travel > 0.0)
    m = moving.size
    dist = travel[moving]
    v_cap = problem.v_cap[moving]
    a_cap = problem.a_fast[moving]  # at most the cap, and the torques allow it at full speed
    v0 = np.asarray(v0, dtype=float)
    a0 = np.asarray(a0, dtype=float)
    t_start, _ = _from_va(travel, np.minimum(v0, problem.v_cap), np.minimum(a0, problem.a_fast))
    t_low, _ = _from_va(dist, v_cap, a_cap)  # fastest under the caps
    t_start = t_start.copy()
    t_start[moving] = np.maximum(t_start[moving], t_low)
    if share_budget:
        scale = np.zeros((travel.size, m))
        scale[moving, np.arange(m)] = t_start[moving]
        z_lo = t_low / t_start[moving]
        z_hi = np.maximum(cycle_time / t_start[moving], z_lo)
    else:
        scale = t_start[:, None].copy()
        z_lo = np.array([np.max(t_low / t_start[moving])])
        z_hi = np.maximum(np.array([cycle_time / np.min(t_start[moving])]), z_lo)
    nz = scale.shape[1]
    ln_a_lo = np.log(np.minimum(4.0 * dist / cycle_time**2, a_cap))
    lower = np.concatenate([z_lo, ln_a_lo])
    upper = np.concatenate([z_hi, np.log(a_cap)])

    def unpack(x: Array) -> tuple[Array, Array, Array]:
        """Rows of x (B, nz + m) -> durations (B, K), moving moves' accelerations and speeds
        (B, m): the smaller root of ``t = D / v + v / a`` (at the triangle limit, ``2 D / t``)."""
        x = np.atleast_2d(x)
        t = x[:, :nz] @ scale.T
        a = np.exp(x[:, nz:])
        tm = t[:, moving]
        root = np.sqrt(np.maximum(a**2 * tm**2 - 4.0 * a * dist, 0.0))
        v = 0.5 * (a * tm - root)
        return t, a, v

    def timing(x: Array) -> tuple[Array, Array]:
        """Durations and ramp fractions (B, K)."""
        t, a, v = unpack(x)
        f = np.ones_like(t)
        f[:, moving] = np.clip(2.0 * v / (a * t[:, moving]), 0.0, 1.0)
        return t, f

    def constraints_fun(x: Array) -> Array:
        """Smooth inequalities (>= 0) of one or more points: reach, speed cap; (B, 2m)."""
        t, a, v = unpack(x)
        reach = np.log(a) + 2.0 * np.log(t[:, moving]) - np.log(4.0 * dist)
        return np.hstack([reach, 1.0 - v / v_cap])

    x0 = np.clip(
        np.concatenate([np.ones(nz), np.log(np.minimum(a0, problem.a_fast)[moving])]), lower, upper
    )
    steps = _FD_STEP * np.maximum(1.0, np.abs(x0))

    def step(x: Array) -> Array:
        """Forward differences, backward at an upper bound."""
        return np.where(x + steps > upper, -steps, steps)

    e_ref = float(abs(problem.evaluate(*timing(x0))[0][0])) or 1.0
    values: dict[bytes, tuple[float, Array]] = {}
    slopes: dict[bytes, tuple[Array, Array]] = {}

    def value(x: Array) -> tuple[float, Array]:
        """Scaled energy and the moving moves' torque ratios at x (a few points cached)."""
        key = x.tobytes()
        if key not in values:
            e, ratio = problem.evaluate(*timing(x))
            if len(values) > 8:
                values.clear()
            values[key] = (float(e[0]) / e_ref, ratio[0, moving])
        return values[key]

    def slope(x: Array) -> tuple[Array, Array]:
        """Forward-difference gradient of the energy and Jacobian of the torque ratios, every
        perturbed program in one batched evaluation."""
        key = x.tobytes()
        if key not in slopes:
            e0, r0 = value(x)
            h = step(x)
            e, ratio = problem.evaluate(*timing(x + np.diag(h)))
            slopes.clear()
            slopes[key] = ((e / e_ref - e0) / h, ((ratio[:, moving] - r0) / h[:, None]).T)
        return slopes[key]

    def cheap_jac(fun: Callable[[Array], Array], x: Array) -> Array:
        """Forward-difference Jacobian of a function of rows of x that needs no model."""
        h = step(x)
        rows = np.asarray(fun(np.vstack([x, x + np.diag(h)])))
        rows = rows[:, None] if rows.ndim == 1 else rows  # (1 + nx, outputs)
        return np.asarray(((rows[1:] - rows[0]) / h[:, None]).T)

    def cycle_fun(x: Array) -> Array:
        return problem.cycle(*timing(x)) / cycle_time - 1.0

    blended = bool(np.any(problem.blends[:-1] > 0.0))
    res = minimize(
        lambda x: value(x)[0],
        x0,
        jac=lambda x: slope(x)[0],
        method="SLSQP",
        bounds=list(zip(lower, upper, strict=True)),
        constraints=[
            {
                "type": "eq",
                "fun": lambda x: float(cycle_fun(x)[0]),
                # without blends the cycle time is the sum of the durations: linear in z
                "jac": (lambda x: cheap_jac(cycle_fun, x)[0])
                if blended
                else (lambda x: np.concatenate([scale.sum(axis=0), np.zeros(m)]) / cycle_time),
            },
            {
                "type": "ineq",
                "fun": lambda x: constraints_fun(x)[0],
                "jac": lambda x: cheap_jac(constraints_fun, x),
            },
            {
                "type": "ineq",
                "fun": lambda x: 1.0 - torque_margin - value(x)[1],
                "jac": lambda x: -slope(x)[1],
            },
        ],
        options={"maxiter": maxiter, "ftol": 1e-8},
    )
    x = np.clip(res.x, lower, upper)
    t, f = timing(x)
    e, _ = problem.evaluate(t, f)
    v, a, _ = _settings(travel, t[0], f[0])
    v = np.where(travel > 0.0, np.minimum(v, problem.v_cap), v0)
    a = np.where(travel > 0.0, np.minimum(a, problem.a_cap), a0)
    return Solution(
        v=v,
        a=a,
        energy=float(e[0]),
        iterations=int(res.nit),
        success=bool(res.success),
        message=str(res.message),
    )


# -- the comparison: program as written, uniform scaling, optimum ---------------------------------


def _per_move(value: ArrayLike | None, moves: int, name: str) -> Array:
    """A per-move setting (NaN = not given), shape (K,)."""
    if value is None:
        return np.full(moves, np.nan)
    arr = np.asarray(value, dtype=float)
    arr = np.full(moves, float(arr)) if arr.ndim == 0 else arr
    if arr.shape != (moves,):
        raise KinergyError(f"{name}: expected one value or {moves} (one per move), got {arr.shape}")
    if np.any(arr[~np.isnan(arr)] <= 0.0) or np.any(np.isinf(arr)):
        raise KinergyError(f"{name}: must be finite and > 0, got {arr.tolist()}")
    return arr


def program_settings(
    problem: TimingProblem, speeds: ArrayLike | None, accels: ArrayLike | None
) -> tuple[Array, Array]:
    """The program as written: the given per-move ``v`` and ``a`` and, where not given (None or
    NaN), the fastest feasible (``v_cap`` and the torque-limited ``a_fast``)."""
    v = _per_move(speeds, problem.moves, "speeds")
    a = _per_move(accels, problem.moves, "accels")
    fast_v = np.where(np.isfinite(problem.v_cap), problem.v_cap, 1.0)
    fast_a = np.where(problem.a_fast > 0.0, problem.a_fast, 1.0)
    return np.where(np.isnan(v), fast_v, v), np.where(np.isnan(a), fast_a, a)


@dataclass(frozen=True, eq=False)
class TimingResult:
    """The program as written, uniform time scaling and the energy-optimal timing at one cycle
    time, each re-simulated at 500 Hz.

    Attributes
    ----------
    cycle_time : float
        The budget, s.
    program, uniform, optimized : ProgramResult
    fastest_cycle_time : float
        Shortest cycle time within the limits (every move at its fastest feasible setting), s.
    v_cap, a_cap : ndarray, shape (K,)
        The optimiser's bounds on each move's ``v`` and ``a`` (``inf``: none but torque).
    active : list of str
        The limits the optimum runs into (one line each).
    iterations : int
        SLSQP iterations (all attempts).
    seconds : float
        Wall time of the optimisation and its verification, s.
    message : str
        The solver's report (and any fallback taken).
    """

    cycle_time: float
    program: ProgramResult
    uniform: ProgramResult
    optimized: ProgramResult
    fastest_cycle_time: float
    v_cap: Array
    a_cap: Array
    active: list[str]
    iterations: int
    seconds: float
    message: str

    @property
    def saving(self) -> float:
        """``1 - E_optimized / E_program`` (fraction)."""
        return 1.0 - self.optimized.e_elec / self.program.e_elec

    @property
    def saving_vs_uniform(self) -> float:
        """``1 - E_optimized / E_uniform`` (fraction)."""
        return 1.0 - self.optimized.e_elec / self.uniform.e_elec

    def to_dict(self) -> dict[str, Any]:
        return {
            "cycle_time": self.cycle_time,
            "fastest_cycle_time": self.fastest_cycle_time,
            "program": self.program.to_dict(),
            "uniform": self.uniform.to_dict(),
            "optimized": self.optimized.to_dict(),
            "saving": self.saving,
            "saving_vs_uniform": self.saving_vs_uniform,
            "saving_percent": 100.0 * self.saving,
            "caps": {
                "v": [float(x) if np.isfinite(x) else None for x in self.v_cap],
                "a": [float(x) if np.isfinite(x) else None for x in self.a_cap],
            },
            "active_limits": list(self.active),
            "solver": {
                "iterations": self.iterations,
                "seconds": self.seconds,
                "message": self.message,
            },
        }


def _scaled_to(
    problem: TimingProblem, v: Array, a: Array, cycle_time: float
) -> tuple[Array, Array]:
    """Settings ``(v, a)`` uniformly scaled so that the program takes ``cycle_time``."""
    t, f = _from_va(problem.travel, v, a)
    total = float(problem.cycle(t[None, :], f[None, :])[0])
    return uniform_scaling(v, a, total / cycle_time)


@dataclass(frozen=True)
class _Checks:
    """How every program of one comparison is re-simulated and checked."""

    robot: Robot
    problem: TimingProblem
    v_max: float | None
    a_max: float | None
    recovery: bool

    def run(self, v: Array, a: Array, label: str, predicted: float | None = None) -> ProgramResult:
        return simulate_program(
            self.robot,
            self.problem.waypoints,
            v,
            a,
            self.problem.blends,
            recovery=self.recovery,
            speed_cap=self.v_max,
            acceleration_cap=self.a_max,
            label=label,
            predicted=predicted,
        )


def _optimum(
    checks: _Checks, cycle_time: float, v0: Array, a0: Array, *, share_budget: bool
) -> tuple[ProgramResult, Solution | None, int]:
    """Solve, re-simulate at 500 Hz, and tighten the bounds by any excess found there (up to
    four attempts). Returns the verified program, the last solution (None at the fastest cycle
    time, which leaves nothing to choose) and the total iterations."""
    problem = checks.problem
    moving = problem.travel > 0.0
    if cycle_time <= problem.fastest_cycle_time * (1.0 + 1e-9):
        v = np.where(moving, problem.v_cap, v0)
        a = np.where(moving, problem.a_fast, a0)
        return checks.run(v, a, "optimized"), None, 0
    current = problem
    margin = 0.0
    iterations = 0
    for _ in range(4):
        sol = solve_timing(
            current, cycle_time, v0=v0, a0=a0, share_budget=share_budget, torque_margin=margin
        )
        iterations += sol.iterations
        result = checks.run(sol.v, sol.a, "optimized", sol.energy)
        over = {
            kind: ratio
            for kind, (ratio, _, _) in result.check.worst().items()
            if ratio > 1.0 + LIMIT_TOL
        }
        if not over or "position" in over:
            break  # (a movej cannot leave the box its waypoints span: nothing to tighten)
        shrink = {
            kind: (1.0 - 1e-6) / over.get(kind, 1.0 - 1e-6) for kind in ("speed", "acceleration")
        }
        a_cap = current.a_cap * shrink["acceleration"]
        current = TimingProblem(
            waypoints=current.waypoints,
            travel=current.travel,
            blends=current.blends,
            v_cap=current.v_cap * shrink["speed"],
            a_cap=a_cap,
            a_fast=np.minimum(current.a_fast * shrink["acceleration"], a_cap),
            evaluate=current.evaluate,
            cycle=current.cycle,
        )
        if "torque" in over:
            margin += over["torque"] - 1.0 + 2e-3
        v0, a0 = sol.v, sol.a
    return result, sol, iterations


def _active(
    robot: Robot,
    problem: TimingProblem,
    result: ProgramResult,
    v_max: float | None,
    a_max: float | None,
) -> list[str]:
    """The limits the optimum runs into: the caps it sits on (per move), torques near theirs."""
    _, _, v_why, a_why = _caps(robot, problem.waypoints, v_max, a_max)
    out = ["cycle time (the budget is used in full)"]
    moving = problem.travel > 0.0
    _, f = _from_va(problem.travel, result.speeds, result.accels)
    # a triangle never reaches its v: only a move that cruises is on its speed cap
    v_on = moving & (result.speeds >= problem.v_cap * (1.0 - 1e-3)) & (f < 1.0 - 1e-6)
    a_on = moving & (result.accels >= problem.a_fast * (1.0 - 1e-3))
    why_a = [
        a_why[k] if problem.a_fast[k] >= problem.a_cap[k] else "torque limits at full speed"
        for k in range(problem.moves)
    ]
    for kind, on, why in (("speed", v_on, v_why), ("acceleration", a_on, why_a)):
        for reason in sorted({why[k] for k in np.flatnonzero(on)}):
            moves = [str(k + 1) for k in np.flatnonzero(on) if why[k] == reason]
            out.append(f"{kind}: {reason} (move{'s' if len(moves) > 1 else ''} {', '.join(moves)})")
    ratio, joint, when = result.check.worst().get("torque", (0.0, "", 0.0))
    if ratio >= 0.98:
        out.append(f"torque: {joint} at {100 * ratio:.1f} % of its limit (t = {when:.2f} s)")
    return out


@_serial
def optimize_timing(
    robot: Robot,
    waypoints: ArrayLike,
    *,
    cycle_time: float | None = None,
    speeds: ArrayLike | None = None,
    accels: ArrayLike | None = None,
    blends: ArrayLike | None = None,
    v_max: float | None = None,
    a_max: float | None = None,
    share_budget: bool = True,
    recovery: bool = True,
    problem: TimingProblem | None = None,
) -> TimingResult:
    """Energy-optimal per-move ``v`` and ``a`` of a movej program for a cycle time.

    Parameters
    ----------
    robot : Robot
    waypoints : array_like, shape (K + 1, n)
        Start pose and the K targets, rad.
    cycle_time : float, optional
        The budget, s; default the program's own cycle time (``--cycle-time same``).
    speeds, accels : float or array_like, shape (K,), optional
        The program as written (rad/s, rad/s^2); NaN or None: the fastest feasible.
    blends : float or array_like, shape (K,), optional
        Joint-space blend radii, rad (kept as given).
    v_max, a_max : float, optional
        Caps on every joint's speed and acceleration besides the robot's limits (the leading
        joint's ``v`` and ``a``). Without ``a_max`` a model without acceleration limits (UR arms)
        is bounded by its torque limits alone.
    share_budget : bool
        Let the optimiser share the budget among the moves (default); otherwise each move keeps
        its share of the program's time.
    recovery : bool
        Braking energy returns to the bus (default, as the seed).
    problem : TimingProblem, optional
        A problem built by :func:`timing_problem` with the same arguments, to reuse it.

    Returns
    -------
    TimingResult
        The program, uniform scaling to ``cycle_time`` (speeds times ``k``, accelerations times
        ``k^2``) and the optimum, each re-simulated at 500 Hz with every limit checked at every
        sample. The optimum is never worse than uniform scaling when that keeps the limits:
        should the solver end above it, uniform scaling is returned (and ``message`` says so).

    Raises
    ------
    KinergyError
        Bad inputs, or a cycle time shorter than the fastest feasible.
    """
    started = time.perf_counter()
    if problem is None:
        problem = timing_problem(
            robot, waypoints, blends=blends, v_max=v_max, a_max=a_max, recovery=recovery
        )
    checks = _Checks(robot, problem, v_max, a_max, recovery)
    v_prog, a_prog = program_settings(problem, speeds, accels)
    program = checks.run(v_prog, a_prog, "program")
    budget = program.cycle_time if cycle_time is None else float(cycle_time)
    fastest = problem.fastest_cycle_time
    if not (np.isfinite(budget) and budget > 0.0):
        raise KinergyError(f"cycle time: must be > 0 s, got {cycle_time}")
    if budget < fastest * (1.0 - 1e-9):
        raise KinergyError(
            f"cycle time {budget:.4g} s is shorter than the fastest feasible {fastest:.4g} s "
            "(every move at its speed, acceleration and torque limits)"
        )
    uniform = checks.run(*uniform_scaling(v_prog, a_prog, program.cycle_time / budget), "uniform")
    v0, a0 = _scaled_to(problem, v_prog, a_prog, budget)
    optimized, sol, iterations = _optimum(checks, budget, v0, a0, share_budget=share_budget)
    message = "fastest cycle time: every move at its limits" if sol is None else sol.message
    # uniform scaling to the budget is the program itself at the program's own cycle time
    if uniform.ok and (not optimized.ok or uniform.e_elec < optimized.e_elec):
        message += (
            f"; the solver ended above uniform scaling ({optimized.e_elec:.6g} J vs "
            f"{uniform.e_elec:.6g} J): kept uniform scaling"
        )
        optimized = checks.run(uniform.speeds, uniform.accels, "optimized")
    return TimingResult(
        cycle_time=budget,
        program=program,
        uniform=uniform,
        optimized=optimized,
        fastest_cycle_time=fastest,
        v_cap=problem.v_cap,
        a_cap=problem.a_cap,
        active=_active(robot, problem, optimized, v_max, a_max),
        iterations=iterations,
        seconds=time.perf_counter() - started,
        message=message,
    )


@dataclass(frozen=True)
class ParetoPoint:
    """Energy at one cycle time: the optimum and uniform scaling of the program, re-simulated at
    500 Hz (J), and whether each keeps every limit at every sample."""

    cycle_time: float
    optimized: float
    uniform: float
    optimized_ok: bool
    uniform_ok: bool

    def to_dict(self) -> dict[str, Any]:
        return {
            "cycle_time": self.cycle_time,
            "optimized": self.optimized,
            "uniform": self.uniform,
            "optimized_within_limits": self.optimized_ok,
            "uniform_within_limits": self.uniform_ok,
        }


@_serial
def pareto_front(
    robot: Robot,
    waypoints: ArrayLike,
    *,
    speeds: ArrayLike | None = None,
    accels: ArrayLike | None = None,
    blends: ArrayLike | None = None,
    v_max: float | None = None,
    a_max: float | None = None,
    cycle_times: Sequence[float] | None = None,
    points: int = 8,
    share_budget: bool = True,
    recovery: bool = True,
    problem: TimingProblem | None = None,
) -> list[ParetoPoint]:
    """Energy against cycle time: the optimum and uniform scaling of the program at each.

    Parameters are those of :func:`optimize_timing`; ``cycle_times`` (s) default to ``points``
    evenly spaced from the fastest feasible to twice the program's, plus the program's own.
    Each optimum starts from the previous one stretched to the next budget.

    Returns
    -------
    list of ParetoPoint
        By increasing cycle time.
    """
    if problem is None:
        problem = timing_problem(
            robot, waypoints, blends=blends, v_max=v_max, a_max=a_max, recovery=recovery
        )
    checks = _Checks(robot, problem, v_max, a_max, recovery)
    v_prog, a_prog = program_settings(problem, speeds, accels)
    t_prog, f_prog = _from_va(problem.travel, v_prog, a_prog)
    own = float(problem.cycle(t_prog[None, :], f_prog[None, :])[0])
    fastest = problem.fastest_cycle_time
    if cycle_times is None:
        if points < 2:
            raise KinergyError(f"points: need at least 2, got {points}")
        times = np.unique(np.append(np.linspace(fastest, max(2.0 * own, fastest), points), own))
    else:
        times = np.sort(np.asarray(cycle_times, dtype=float))
        if times.size == 0 or not np.all(np.isfinite(times)) or times[0] < fastest * (1 - 1e-9):
            raise KinergyError(
                f"cycle_times: each must be at least the fastest feasible {fastest:.4g} s"
            )
    out = []
    v0, a0 = v_prog, a_prog
    for budget in times:
        uniform = checks.run(*uniform_scaling(v_prog, a_prog, own / budget), "uniform")
        v0, a0 = _scaled_to(problem, v0, a0, float(budget))
        best, _, _ = _optimum(checks, float(budget), v0, a0, share_budget=share_budget)
        if uniform.ok and (not best.ok or uniform.e_elec < best.e_elec):
            best = uniform
        out.append(
            ParetoPoint(
                cycle_time=float(budget),
                optimized=best.e_elec,
                uniform=uniform.e_elec,
                optimized_ok=best.ok,
                uniform_ok=uniform.ok,
            )
        )
        v0, a0 = best.speeds, best.accels
    return out
