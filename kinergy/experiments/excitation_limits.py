"""The limits an excitation keeps (nursing eq 23), as constraints and as a final check.

At every grid point: ``lower <= q <= upper`` (the robot's range, tightened to
``start +- position_range``), ``|qd| <= speed``, ``|qdd| <= acceleration`` (the robot's; where
the model has none, :data:`ACCELERATION_PER_SPEED` times the speed limit), and the height of the
flange (``floor_frames="flange"``) or of the flange and every link frame from the second on
(``"links"``, the default: elbow, wrists, flange on a UR arm) at least ``floor`` above the base
plane (``z = 0`` of the base frame). Self-collision is not modelled: ``position_range`` (default
+-90 deg about the start) keeps an arm from folding onto itself.

The optimiser sees the limits 1 % tighter than they are (:meth:`ExcitationLimits.tightened`) and
each limit through the margins at its few lowest local minima on a grid (:func:`constraints`),
with exact Jacobians: constant for positions, speeds and accelerations, from the frames'
geometric Jacobians for the floor. The result is checked at every ``dt`` sample and, should a
sample still overshoot between grid points, the whole trajectory is scaled toward the start pose
until none does (:func:`fit_into_limits`; scaling keeps the boundary conditions).
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
from numpy.typing import ArrayLike, NDArray

from kinergy import checks
from kinergy.arrays import Array
from kinergy.dynamics.chain import kernel_data
from kinergy.dynamics.kinematics import joint_axes
from kinergy.errors import KinergyError
from kinergy.experiments.excitation_series import SeriesGrid
from kinergy.model.robot import Robot
from kinergy.trajectory.motion import Motion

__all__ = [
    "ACCELERATION_PER_SPEED",
    "DEFAULT_RANGE",
    "FLOOR_FRAMES",
    "ExcitationLimits",
    "constraints",
    "constraints_jacobian",
    "excitation_limits",
    "fit_into_limits",
    "frame_heights",
]


#: frames kept above the floor: the flange only, or the flange and every link frame from the second
FLOOR_FRAMES = ("flange", "links")
#: default half-width of each joint's range about the start pose, rad (+-90 deg)
DEFAULT_RANGE = np.pi / 2
#: acceleration limit per unit speed limit, 1/s, for joints whose model publishes none
ACCELERATION_PER_SPEED = 2.0
#: the 6-joint start pose when none is given: UR's upright "home" (the twin's test programs' too)
_HOME_6 = np.array([0.0, -np.pi / 2, 0.0, -np.pi / 2, 0.0, 0.0])
#: the optimiser sees the limits this fraction tighter (grid points miss peaks in between)
_GRID_MARGIN = 0.01
#: ... and the floor this much higher, m
_FLOOR_MARGIN = 5e-4
#: local minima of each limit's margin that are constrained (per joint, per checked frame)
_ACTIVE = 6


@dataclass(frozen=True, eq=False)
class ExcitationLimits:
    """What every sample of an excitation keeps (module docstring).

    Attributes
    ----------
    start : ndarray, shape (n,)
        Start (and end) pose, rad.
    lower, upper : ndarray, shape (n,)
        Position bounds, rad.
    speed, acceleration : ndarray, shape (n,)
        Limits, rad/s and rad/s^2.
    floor : float or None
        Minimum height of the checked frames above the base plane, m (None: no floor).
    floor_frames : {"flange", "links"}
    """

    start: Array
    lower: Array
    upper: Array
    speed: Array
    acceleration: Array
    floor: float | None
    floor_frames: str

    def tightened(self) -> ExcitationLimits:
        """The limits the optimiser sees: 1 % of each range, speed and acceleration tighter (never
        past the start pose) and the floor 0.5 mm higher."""
        half = 0.5 * (self.upper - self.lower)
        return replace(
            self,
            lower=np.minimum(self.lower + _GRID_MARGIN * half, self.start),
            upper=np.maximum(self.upper - _GRID_MARGIN * half, self.start),
            speed=(1.0 - _GRID_MARGIN) * self.speed,
            acceleration=(1.0 - _GRID_MARGIN) * self.acceleration,
            floor=None if self.floor is None else self.floor + _FLOOR_MARGIN,
        )

    def margins(self, q: Array, qd: Array, qdd: Array) -> Array:
        """Room to the six linear limits at states (N, n), shape (6, N, n): ``upper - q``,
        ``q - lower``, ``v - qd``, ``v + qd``, ``a - qdd``, ``a + qdd``."""
        v, acc = self.speed, self.acceleration
        return np.stack([self.upper - q, q - self.lower, v - qd, v + qd, acc - qdd, acc + qdd])

    def check(self, robot: Robot, motion: Motion) -> dict[str, float]:
        """Smallest room to each limit over the samples of ``motion`` (>= 0: met).

        Keys ``position`` (rad), ``speed`` (rad/s), ``acceleration`` (rad/s^2), ``floor`` (m,
        absent without a floor), and ``boundary``: the largest of ``|q - start|``, ``|qd|``,
        ``|qdd|`` at the first and last samples (zero up to round-off by construction).
        """
        q, qd, qdd = motion.q, motion.qd, motion.qdd
        out = {
            "position": float(min(np.min(self.upper - q), np.min(q - self.lower))),
            "speed": float(np.min(self.speed - np.abs(qd))),
            "acceleration": float(np.min(self.acceleration - np.abs(qdd))),
        }
        if self.floor is not None:
            heights, _ = frame_heights(robot, q, self.floor_frames, jacobian=False)
            out["floor"] = float(np.min(heights) - self.floor)
        ends = [q[0] - self.start, q[-1] - self.start, qd[0], qd[-1], qdd[0], qdd[-1]]
        out["boundary"] = float(max(np.max(np.abs(x)) for x in ends))
        return out

    def to_dict(self) -> dict[str, object]:
        """The bounds and limits (the ``excite --json`` ``limits`` object)."""
        return {
            "lower": self.lower.tolist(),
            "upper": self.upper.tolist(),
            "speed": self.speed.tolist(),
            "acceleration": self.acceleration.tolist(),
            "floor": self.floor,
        }


# ---------------------------------------------------------------------------------------------
# Building the limits


def _as_vector(value: ArrayLike, n: int, what: str) -> Array:
    arr = np.asarray(value, dtype=float)
    if arr.ndim == 0:
        arr = np.full(n, float(arr))
    if arr.shape != (n,) or not np.all(np.isfinite(arr)):
        raise KinergyError(f"{what}: expected a number or {n} finite numbers, got {arr.tolist()}")
    return arr


def _start_pose(robot: Robot, start: ArrayLike | None) -> Array:
    """The start pose (n,), rad: ``start`` within the limits, or UR's home on a 6-joint arm,
    else the middle of each joint's range (clipped to +-pi)."""
    limits = np.array([j.limits.position for j in robot.joints])
    if start is None:
        clipped = np.clip(limits, -np.pi, np.pi)
        home = _HOME_6 if robot.n == 6 else 0.5 * (clipped[:, 0] + clipped[:, 1])
        return np.clip(home, limits[:, 0], limits[:, 1])
    q_start = _as_vector(start, robot.n, "start pose")
    outside = np.flatnonzero((q_start < limits[:, 0]) | (q_start > limits[:, 1]))
    if outside.size:
        j = int(outside[0])
        raise KinergyError(
            f"start pose: joint {j + 1} ({robot.joints[j].name}) at {q_start[j]:.4g} rad is "
            f"outside its limits [{limits[j, 0]:.4g}, {limits[j, 1]:.4g}]"
        )
    return q_start


def _position_bounds(
    robot: Robot, q_start: Array, position_range: float | ArrayLike | None
) -> tuple[Array, Array]:
    """``lower``, ``upper`` (n,): the robot's range, within ``start +- position_range``."""
    limits = np.array([j.limits.position for j in robot.joints])
    lower, upper = limits[:, 0].copy(), limits[:, 1].copy()
    if position_range is not None:
        half = checks.vector(
            _as_vector(position_range, robot.n, "position range"), "position range", gt=0.0
        )
        lower = np.maximum(lower, q_start - half)
        upper = np.minimum(upper, q_start + half)
    if np.any(upper - lower <= 0):
        j = int(np.argmin(upper - lower))
        raise KinergyError(f"joint {j + 1} ({robot.joints[j].name}) has no room to move")
    return lower, upper


def _rate_limits(
    robot: Robot, speed: float | ArrayLike | None, acceleration: float | ArrayLike | None
) -> tuple[Array, Array]:
    """Speed (rad/s, at most the robot's) and acceleration (rad/s^2) limits, shape (n,) each."""
    n = robot.n
    robot_speed = np.array([j.limits.speed for j in robot.joints])
    v = robot_speed if speed is None else np.minimum(_as_vector(speed, n, "speed"), robot_speed)
    if acceleration is None:
        published = [j.limits.acceleration for j in robot.joints]
        acc = np.array(
            [ACCELERATION_PER_SPEED * v[i] if a is None else a for i, a in enumerate(published)]
        )
    else:
        acc = _as_vector(acceleration, n, "acceleration")
    for name, arr, unit in (("speed", v, "rad/s"), ("acceleration", acc, "rad/s²")):
        if np.any(arr <= 0):
            j = int(np.argmin(arr))
            raise KinergyError(
                f"{name} limit of joint {j + 1} ({robot.joints[j].name}) must be > 0 {unit}, "
                f"got {arr[j]:g}"
            )
    return v, acc


def _check_floor(robot: Robot, q_start: Array, floor: float | None, floor_frames: str) -> None:
    """The floor option is a finite height the start pose keeps every checked frame above."""
    if floor_frames not in FLOOR_FRAMES:
        raise KinergyError(
            f"unknown floor_frames {floor_frames!r} (known: {', '.join(FLOOR_FRAMES)})"
        )
    if floor is None:
        return
    floor = checks.number(floor, "floor")
    heights, _ = frame_heights(robot, q_start[None, :], floor_frames, jacobian=False)
    if np.min(heights) <= floor:
        raise KinergyError(
            f"the start pose puts a checked frame {np.min(heights):.3f} m above the base "
            f"plane, not above the floor at {floor:g} m: choose another start pose or floor"
        )


def excitation_limits(
    robot: Robot,
    *,
    start: ArrayLike | None = None,
    position_range: float | ArrayLike | None = DEFAULT_RANGE,
    speed: float | ArrayLike | None = None,
    acceleration: float | ArrayLike | None = None,
    floor: float | None = 0.05,
    floor_frames: str = "links",
) -> ExcitationLimits:
    """The limits of an excitation of ``robot`` (module docstring).

    Parameters
    ----------
    robot : Robot
    start : array_like, shape (n,), optional
        Start and end pose, rad. Default: UR's upright home ``[0, -pi/2, 0, -pi/2, 0, 0]`` for a
        6-joint arm, else the middle of each joint's range (clipped to +-pi); clipped to the limits.
    position_range : float or array_like, shape (n,), optional
        Half-width of each joint's range about ``start``, rad, intersected with the robot's
        limits; ``None`` for the robot's limits alone.
    speed : float or array_like, optional
        Speed limit, rad/s; default and upper bound the robot's.
    acceleration : float or array_like, optional
        Acceleration limit, rad/s^2; default the robot's, or :data:`ACCELERATION_PER_SPEED` times
        the speed limit where the model has none.
    floor : float or None
        Height above the base plane the checked frames must keep, m; ``None``: no floor.
    floor_frames : {"links", "flange"}
        The flange and every link frame from the second on, or the flange alone.

    Raises
    ------
    KinergyError
        A start pose outside the limits or below the floor, a non-positive range, speed or
        acceleration, a joint without room to move, an unknown ``floor_frames``.
    """
    q_start = _start_pose(robot, start)
    lower, upper = _position_bounds(robot, q_start, position_range)
    v, acc = _rate_limits(robot, speed, acceleration)
    _check_floor(robot, q_start, floor, floor_frames)
    return ExcitationLimits(
        q_start, lower, upper, v, acc, None if floor is None else float(floor), floor_frames
    )


# ---------------------------------------------------------------------------------------------
# The floor


def frame_heights(
    robot: Robot, q: Array, floor_frames: str, *, jacobian: bool
) -> tuple[Array, Array | None]:
    """Heights (m) of the checked frames at poses ``q`` (N, n), (N, F), and their derivatives
    with respect to the joint angles, (N, F, n) (None unless ``jacobian``).

    The frames are the flange (``"flange"``) or every link frame from the second on and the
    flange (``"links"``); a height's derivative is the z component of ``axis x lever``.
    """
    chain = kernel_data(robot).chain  # built once per robot
    axes, points, link = joint_axes(chain, q)
    flange = (link[:, -1] @ chain.flange)[:, :3, 3]
    n = robot.n
    if floor_frames == "links":
        pos = np.concatenate([link[:, 1:, :3, 3], flange[:, None, :]], axis=1)
        moved_by = [*range(2, n + 1), n]  # frame k is moved by joints 0..k
    else:
        pos = flange[:, None, :]
        moved_by = [n]
    heights = pos[:, :, 2]
    if not jacobian:
        return heights, None
    lever = pos[:, :, None, :] - points[:, None, :, :]  # (N, F, n, 3)
    dh = axes[:, None, :, 0] * lever[..., 1] - axes[:, None, :, 1] * lever[..., 0]
    for f, count in enumerate(moved_by):
        dh[:, f, count:] = 0.0
    return heights, dh


# ---------------------------------------------------------------------------------------------
# Constraints for the optimiser


def _lowest_minima(margins: Array, k: int) -> NDArray[np.intp]:
    """Rows (k, m) of the ``k`` lowest local minima of each column of ``margins`` (Nc, m), a
    periodic grid; columns with fewer minima are filled with their lowest other rows."""
    is_min = (margins <= np.roll(margins, 1, axis=0)) & (margins <= np.roll(margins, -1, axis=0))
    span = np.ptp(margins, axis=0) + 1.0
    key = np.where(is_min, margins, margins + span)
    return np.argsort(key, axis=0, kind="stable")[:k]


def constraints(robot: Robot, limits: ExcitationLimits, grid: SeriesGrid, zz: Array) -> Array:
    """Inequality constraints, ``>= 0`` when met, of unknowns ``zz`` (k, n) on ``grid``.

    Each limit of each joint (and the floor for each checked frame) contributes the margins at
    its :data:`_ACTIVE` lowest local minima on the grid: a peak that approaches a limit is
    constrained wherever it moves, with a few hundred constraints instead of one per grid point
    and limit. Pass :meth:`ExcitationLimits.tightened` limits.
    """
    q, qd, qdd = grid.states(limits.start, zz)
    margins = limits.margins(q, qd, qdd)
    out = [np.take_along_axis(m, _lowest_minima(m, _ACTIVE), axis=0).reshape(-1) for m in margins]
    if limits.floor is not None:
        heights, _ = frame_heights(robot, q, limits.floor_frames, jacobian=False)
        room = heights - limits.floor
        out.append(np.take_along_axis(room, _lowest_minima(room, _ACTIVE), axis=0).reshape(-1))
    return np.concatenate(out)


def constraints_jacobian(
    robot: Robot, limits: ExcitationLimits, grid: SeriesGrid, zz: Array
) -> Array:
    """Jacobian of :func:`constraints` with respect to the flat unknowns, (constraints, k n)."""
    q, qd, qdd = grid.states(limits.start, zz)
    margins = limits.margins(q, qd, qdd)
    k_free, n = zz.shape
    blocks = []
    for kind, m in enumerate(margins):
        basis = grid.bases[kind // 2]
        sign = -1.0 if kind % 2 == 0 else 1.0
        idx = _lowest_minima(m, _ACTIVE)  # (k, n)
        jac = np.zeros((_ACTIVE, n, k_free, n))
        for j in range(n):
            jac[:, j, :, j] = sign * basis[idx[:, j]]
        blocks.append(jac.reshape(_ACTIVE * n, -1))
    if limits.floor is not None:
        heights, dh = frame_heights(robot, q, limits.floor_frames, jacobian=True)
        assert dh is not None
        idx = _lowest_minima(heights - limits.floor, _ACTIVE)  # (k, F)
        frames = np.arange(heights.shape[1])[None, :]
        # d h[s, f] / d Z[k, j] = dh[s, f, j] * q_basis[s, k]
        jac_f = np.einsum("rfj,rfk->rfkj", dh[idx, frames], grid.q_basis[idx])
        blocks.append(jac_f.reshape(idx.size, -1))
    return np.vstack(blocks)


# ---------------------------------------------------------------------------------------------
# Scaling into the limits


def _linear_scale(limits: ExcitationLimits, grid: SeriesGrid, zz: Array) -> float:
    """Largest factor ``s`` with ``s Z`` inside the position, speed and acceleration limits at
    every point of ``grid``."""
    dq, qd, qdd = (basis @ zz for basis in grid.bases)
    up, lo = limits.upper - limits.start, limits.lower - limits.start
    room_up = np.where(dq > 0, up / np.where(dq > 0, dq, 1.0), np.inf)
    room_lo = np.where(dq < 0, lo / np.where(dq < 0, dq, 1.0), np.inf)
    top = [
        float(np.min(room_up)),
        float(np.min(room_lo)),
        float(np.min(limits.speed / np.maximum(np.max(np.abs(qd), axis=0), 1e-300))),
        float(np.min(limits.acceleration / np.maximum(np.max(np.abs(qdd), axis=0), 1e-300))),
    ]
    return min(top)


def _above_floor(
    robot: Robot, limits: ExcitationLimits, grid: SeriesGrid, zz: Array, scale: float
) -> bool:
    """Whether ``scale * Z`` keeps the checked frames above the floor at every point of ``grid``."""
    q = limits.start + scale * (grid.q_basis @ zz)
    heights, _ = frame_heights(robot, q, limits.floor_frames, jacobian=False)
    assert limits.floor is not None
    return bool(np.all(heights >= limits.floor))


def fit_into_limits(
    robot: Robot,
    limits: ExcitationLimits,
    grids: tuple[SeriesGrid, SeriesGrid],
    zz: Array,
    *,
    safety: float = 1.0 - 1e-9,
) -> Array:
    """``s Z`` with the largest ``s <= 1`` that meets every limit at every point of the fine grid,
    times ``safety`` when it had to shrink; ``grids`` = (constraint grid, fine grid).

    Positions, speeds and accelerations scale linearly. The floor's factor is found by bisection
    on the constraint grid (the start pose is above the floor), then shrunk by 1 % steps until
    every point of the fine grid is above it too.
    """
    coarse, fine = grids
    s = min(1.0, safety * _linear_scale(limits, fine, zz))
    if limits.floor is not None and not _above_floor(robot, limits, fine, zz, s):
        lo, hi = 0.0, s
        for _ in range(30):
            mid = 0.5 * (lo + hi)
            lo, hi = (mid, hi) if _above_floor(robot, limits, coarse, zz, mid) else (lo, mid)
        s = safety * lo
        while not _above_floor(robot, limits, fine, zz, s):
            s *= 0.99
    return np.asarray(s * zz)
