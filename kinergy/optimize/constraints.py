"""The joints' limits as constraints: checks at every sample and the optimiser's torque bound.

:func:`limit_violations` checks a motion against every joint's position, speed, acceleration and
torque limits (and an optimiser's own caps) at every sample: what verifies a result at 500 Hz.
:func:`torque_ratio` is the constraint the solver keeps during the search: per move, the largest
joint torque over its limit at the quadrature nodes inside the move. The joint torque is the motor
torque reflected to the joint, ``N^T tau_m`` (:func:`kinergy.drives.transmission.joint_torque`),
friction included: what the joint's gearbox carries.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from kinergy.arrays import Array
from kinergy.drives.transmission import joint_torque
from kinergy.model.robot import Robot
from kinergy.optimize.samples import ProgramSamples
from kinergy.predict import DriveState
from kinergy.trajectory.motion import Motion

__all__ = ["LIMIT_TOL", "LimitCheck", "limit_violations", "torque_ratio"]


#: a sample is within a limit when ``|x| / limit <= 1 + LIMIT_TOL``
LIMIT_TOL = 1e-9


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
        The drive model over ``motion`` (:func:`kinergy.predict.drive_state`); the joint
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
    with np.errstate(invalid="ignore", divide="ignore"):  # a zero cap: 0/0 where nothing moves
        acc_ratio = np.where(np.isfinite(acc), np.abs(motion.qdd) / acc, np.nan)
        speed_ratio = np.abs(motion.qd) / speed
    return LimitCheck(
        joints=robot.joint_names,
        t=motion.t,
        ratios={
            "position": np.abs(motion.q - 0.5 * (lo + hi)) / (0.5 * (hi - lo)),
            "speed": speed_ratio,
            "acceleration": acc_ratio,
            "torque": np.abs(joint_torque(robot, state.tau_m)) / torque,
        },
    )


def torque_ratio(robot: Robot, samples: ProgramSamples) -> Array:
    """Per program and move the largest ``|tau_joint| / limit`` over the joints and the samples
    within the move's span, shape (B, K) (at most 1: the torque limits hold)."""
    limit = np.array([j.limits.torque for j in robot.joints])
    ratio = np.abs(joint_torque(robot, samples.drive.tau_m)) / limit
    return samples.move_max(ratio.max(axis=1))
