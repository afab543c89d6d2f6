"""The nursing doc's excitation trajectory (nursing section 4.2, eq 22, Table 6).

Table 6 prints the coefficients of a three-harmonic Fourier series per joint (eq 22, base
frequency ``w_f = 0.2 pi`` rad/s, a 10 s period) that the doc optimised for its robot (eq 23).
:func:`table6_motion` runs it, through :func:`kinergy.trajectory.fourier.fourier_motion`, inside
a robot's limits.
"""

from __future__ import annotations

import numpy as np

from kinergy.arrays import Array
from kinergy.errors import KinergyError
from kinergy.experiments.nursing_doc import BASE_FREQUENCY, DOC_TABLE6
from kinergy.model.robot import Robot
from kinergy.trajectory.fourier import fourier_motion
from kinergy.trajectory.motion import CONTROLLER_DT, Motion

__all__ = ["table6_motion"]


def _limit_scales(robot: Robot, q0: Array, one: Motion) -> tuple[Array, list[str]]:
    """Per joint, the factor (<= 1) on Table 6's harmonics that keeps one period of ``one``
    inside the joint's position and speed limits (0.98 of the room left), and a note per
    scaled joint."""
    scale = np.ones(robot.n)
    notes = []
    for j, joint in enumerate(robot.joints):
        lo, hi = joint.limits.position
        if not lo < q0[j] < hi:
            raise KinergyError(
                f"Table 6's q0 = {q0[j]:g} rad of joint {j + 1} is outside {joint.name}'s range"
            )
        swing = one.q[:, j] - q0[j]
        room = min(
            (hi - q0[j]) / max(float(swing.max()), 1e-12),
            (q0[j] - lo) / max(float(-swing.min()), 1e-12),
            joint.limits.speed / float(np.abs(one.qd[:, j]).max()),
        )
        if room < 1.0:
            scale[j] = 0.98 * room
            notes.append(
                f"joint {j + 1} ({joint.name}): Table 6's trajectory leaves its limits; "
                f"coefficients scaled by {scale[j]:.3f}"
            )
    return scale, notes


def table6_motion(
    robot: Robot, *, periods: int = 10, dt: float = CONTROLLER_DT
) -> tuple[Motion, Array, list[str]]:
    """The doc's excitation (eq 22 with Table 6, ``w_f = 0.2 pi``, N = 3), inside the limits.

    A joint whose angles or speeds would leave the robot's limits has its harmonics scaled down
    (about ``q0``) until they fit; the notes say which and by how much.

    Parameters
    ----------
    robot : Robot
        Six joints (Table 6's rows).
    periods : int
        Whole periods of 10 s.
    dt : float
        Sample time, s.

    Returns
    -------
    motion : Motion
        ``periods`` periods of 10 s at ``dt``.
    scale : ndarray, shape (n,)
        Factor applied to each joint's coefficients (1 = as printed).
    notes : list of str
    """
    if robot.n != 6:
        raise KinergyError(f"Table 6's excitation is for 6 joints; {robot.name} has {robot.n}")
    a = np.array(DOC_TABLE6["a"])
    b = np.array(DOC_TABLE6["b"])
    q0 = np.array(DOC_TABLE6["q0"])
    one = fourier_motion(q0, a, b, base_frequency=BASE_FREQUENCY, periods=1, dt=min(dt, 0.01))
    scale, notes = _limit_scales(robot, q0, one)
    motion = fourier_motion(
        q0,
        a * scale[:, None],
        b * scale[:, None],
        base_frequency=BASE_FREQUENCY,
        periods=periods,
        dt=dt,
    )
    return motion, scale, notes
