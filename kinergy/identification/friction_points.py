"""Friction from constant-speed back-and-forth runs in a log (nursing section 4.1, eqs 19-20).

At constant speed a joint needs no inertial torque, so its torque from the motor currents
(nursing eq 21, :func:`kinergy.drives.coupled.joint_torques_from_current`) is friction plus what
does not depend on the direction of motion (gravity, modelling error). Friction is odd in the speed
and the rest even (eq 19), so ``tau_f(v) = (T(v) - T(-v)) / 2`` and the modelling error
``tau_n = (T(v) + T(-v)) / 2`` (eq 20):

- :func:`constant_speed_runs`: the runs at ``+v`` and ``-v`` in a joint's commanded speed;
- :func:`odd_even_friction`: eqs 19-20;
- :func:`friction_points`: the friction per speed level and per sample (:class:`FrictionPoints`),
  pairing equal positions so that position-dependent torques cancel.

The runs themselves are designed in :mod:`kinergy.experiments.friction_runs`.
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from kinergy.arrays import Array
from kinergy.errors import KinergyError

__all__ = ["FrictionPoints", "constant_speed_runs", "friction_points", "odd_even_friction"]


def odd_even_friction(
    speed_levels: ArrayLike, torque_forward: ArrayLike, torque_backward: ArrayLike
) -> tuple[Array, Array]:
    """Eqs 19-20: friction as the odd part, modelling error as the even part.

    ``tau_f(v) = (T(v) - T(-v)) / 2`` and ``tau_n(v) = (T(v) + T(-v)) / 2``, where ``T(v)`` is the
    torque moving at ``+v`` and ``T(-v)`` at ``-v`` (same positions). Works per level (means) or
    per sample.

    Parameters
    ----------
    speed_levels : array_like, shape (L,)
        ``v`` > 0, rad/s (checked; the results are ``tau_f(v)``, ``tau_n(v)`` at these speeds).
    torque_forward, torque_backward : array_like, shape (L,) or (L, ...)
        ``T(v)`` and ``T(-v)``, N m.

    Returns
    -------
    friction, error : ndarray, shape like the torques
        ``tau_f(v)`` and ``tau_n(v)``, N m.
    """
    v = np.asarray(speed_levels, dtype=float)
    fwd = np.asarray(torque_forward, dtype=float)
    bwd = np.asarray(torque_backward, dtype=float)
    if fwd.shape != bwd.shape or fwd.shape[:1] != v.shape[:1] or v.ndim != 1:
        raise KinergyError(
            f"odd/even split: speeds {v.shape} and torques {fwd.shape}, {bwd.shape} do not match"
        )
    if not np.all(v > 0):
        raise KinergyError("odd/even split: speed levels must be > 0 (T(v) moves at +v)")
    return 0.5 * (fwd - bwd), 0.5 * (fwd + bwd)


@dataclass(frozen=True, eq=False)
class FrictionPoints:
    """Friction of one joint from back-and-forth runs (joint side).

    Attributes
    ----------
    joint : int
    speeds, friction, error : ndarray, shape (L,)
        Speed levels (rad/s), the odd part (friction) and the even part (modelling error and
        gravity) of the level means, N m.
    sample_speeds, sample_friction : ndarray, shape (M,)
        The odd part per forward sample (paired with the backward sample at the same position):
        the scatter the doc's Figure 8 plots.
    """

    joint: int
    speeds: Array
    friction: Array
    error: Array
    sample_speeds: Array
    sample_friction: Array


def friction_points(
    position: ArrayLike,
    torque: ArrayLike,
    speeds: ArrayLike,
    forward: ArrayLike,
    backward: ArrayLike,
    *,
    joint: int = 0,
    trim: int = 10,
) -> FrictionPoints:
    """Odd and even parts of one joint's torque over its constant-speed runs (eqs 19-20).

    Each forward sample is paired with the backward run's torque at the same position (linear
    interpolation), so position-dependent torques (gravity) cancel in the odd part even when the
    axis is not vertical.

    Parameters
    ----------
    position, torque : array_like, shape (N,)
        The joint's angle (rad; the real motion) and torque (N m).
    speeds : array_like, shape (L,)
        rad/s.
    forward, backward : array_like of int, shape (L, 2)
        ``[start, stop)`` of each level's runs at ``+v`` and ``-v``.
    trim : int
        Samples dropped at both ends of each run (the real motion's lag, filter transients).
    """
    q = np.asarray(position, dtype=float)
    tau = np.asarray(torque, dtype=float)
    v = np.asarray(speeds, dtype=float)
    fwd_idx = np.asarray(forward, dtype=int)
    bwd_idx = np.asarray(backward, dtype=int)
    levels, s_v, s_f, mean_f, mean_b = [], [], [], [], []
    for k, speed in enumerate(v):
        f0, f1 = fwd_idx[k, 0] + trim, fwd_idx[k, 1] - trim
        b0, b1 = bwd_idx[k, 0] + trim, bwd_idx[k, 1] - trim
        if f1 - f0 < 2 or b1 - b0 < 2:
            continue
        qf, tf = q[f0:f1], tau[f0:f1]
        qb, tb = q[b0:b1][::-1], tau[b0:b1][::-1]  # increasing positions
        inside = (qf >= qb[0]) & (qf <= qb[-1])
        if inside.sum() < 2:
            continue
        tb_at = np.interp(qf[inside], qb, tb)
        odd, _ = odd_even_friction(np.full(inside.sum(), speed), tf[inside], tb_at)
        levels.append(speed)
        mean_f.append(float(np.mean(tf[inside])))
        mean_b.append(float(np.mean(tb_at)))
        s_v.append(np.full(odd.size, speed))
        s_f.append(odd)
    if not levels:
        raise KinergyError(
            f"joint {joint + 1}: no forward and backward constant-speed runs over the same positions"
        )
    lv = np.array(levels)
    fric, err = odd_even_friction(lv, np.array(mean_f), np.array(mean_b))
    return FrictionPoints(joint, lv, fric, err, np.concatenate(s_v), np.concatenate(s_f))


def constant_speed_runs(
    qd: ArrayLike,
    qdd: ArrayLike,
    *,
    min_speed: float = 1e-3,
    acc_tol: float = 0.05,
    min_samples: int = 20,
    rtol: float = 0.01,
) -> tuple[Array, NDArray[np.int_], NDArray[np.int_]]:
    """Find the back-and-forth runs in one joint's commanded speed (for logs without run indices).

    A run is a maximal stretch where ``|qd| > min_speed`` with one sign and ``|qdd| < acc_tol``
    (rad/s^2), at least ``min_samples`` long. Each run at ``+v`` is paired with the next run at
    ``-v`` whose speed is within ``rtol``.

    Returns
    -------
    speeds : ndarray, shape (L,)
    forward, backward : ndarray of int, shape (L, 2)
        As :class:`kinergy.experiments.friction_runs.FrictionRun`'s.
    """
    v = np.asarray(qd, dtype=float)
    a = np.asarray(qdd, dtype=float)
    steady = (np.abs(v) > min_speed) & (np.abs(a) < acc_tol)
    sign = np.where(steady, np.sign(v), 0).astype(int)
    edges = np.flatnonzero(np.diff(np.concatenate([[0], sign, [0]])))
    runs: list[tuple[int, int, float]] = []
    for a0, a1 in itertools.pairwise(edges):
        if sign[a0] != 0 and a1 - a0 >= min_samples and np.all(sign[a0:a1] == sign[a0]):
            runs.append((int(a0), int(a1), float(np.median(v[a0:a1]))))
    speeds: list[float] = []
    forward: list[tuple[int, int]] = []
    backward: list[tuple[int, int]] = []
    used: set[int] = set()
    for i, (s, e, speed) in enumerate(runs):
        if speed <= 0:
            continue
        for j in range(i + 1, len(runs)):
            s2, e2, speed2 = runs[j]
            if j not in used and speed2 < 0 and abs(abs(speed2) - speed) <= rtol * speed:
                used.add(j)
                speeds.append(speed)
                forward.append((s, e))
                backward.append((s2, e2))
                break
    return (
        np.array(speeds),
        np.array(forward, dtype=np.int_).reshape(-1, 2),
        np.array(backward, dtype=np.int_).reshape(-1, 2),
    )
