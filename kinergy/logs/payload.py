"""The payload the controller logged: what the arm carried, sample by sample.

A UR controller logs the payload it was told to carry (``set_target_payload`` or the
installation's): ``payload`` (kg), ``payload_cog`` (its centre of gravity, m, in the tool flange
frame) and ``payload_inertia`` (kg m² about the centre of gravity, axes along the flange's, in
UR's order ``[Ixx, Iyy, Izz, Ixy, Ixz, Iyz]``: UR's script manual, ``set_target_payload``).
kinergy's :class:`~kinergy.model.robot.Payload` holds the same load in the flange frame
(:attr:`~kinergy.model.robot.Robot.flange`: the DH frame 6 for UR arms, which is UR's tool
flange frame), its inertia in kinergy's order ``[Ixx, Iyy, Izz, Ixy, Iyz, Ixz]``
(:func:`from_columns` reorders it).

Where a log has ``payload``, it is the payload of every command that reads the log, sample by
sample (:func:`logged_loads`), unless ``--payload`` replaces it. A logged payload is checked as
any input is (:func:`payload_problem`): a mass or a centre of gravity the arm could not hold is
the ``ratings`` check's failure.

Examples
--------
>>> import numpy as np
>>> p = from_columns(np.array([1.07, 0, 0, 0.058, 0.4, 0.5, 0.6, 0.01, 0.02, 0.03]))
>>> p.mass, p.com.tolist(), p.inertia.tolist()
(1.07, [0.0, 0.0, 0.058], [0.4, 0.5, 0.6, 0.01, 0.03, 0.02])
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from numpy.typing import NDArray

from kinergy.arrays import Array
from kinergy.dynamics.rnea import gravity_torque
from kinergy.errors import KinergyError
from kinergy.io.log import Log
from kinergy.model.robot import PAYLOAD_REACH, Payload, Robot

__all__ = [
    "PAYLOAD_SIGNALS",
    "describe",
    "from_columns",
    "logged_loads",
    "payload_columns",
    "payload_problem",
    "with_logged",
]

#: the fields of a log that say what payload the arm carried
PAYLOAD_SIGNALS = ("payload", "payload_cog", "payload_inertia")

#: UR's ``payload_inertia`` order [Ixx, Iyy, Izz, Ixy, Ixz, Iyz] -> kinergy's [.., Ixy, Iyz, Ixz]
_UR_TO_KINERGY = [0, 1, 2, 3, 5, 4]


def payload_columns(log: Log) -> Array | None:
    """The logged payload per sample as columns ``[mass, cog (3), inertia (6, UR's order)]``,
    shape (N, 10), or None when the log has no ``payload`` (a missing centre of gravity or
    inertia is zero: a point mass at the flange)."""
    if "payload" not in log:
        return None
    n = len(log)
    out = np.zeros((n, 10))
    out[:, 0] = log["payload"]
    for name, cols in (("payload_cog", slice(1, 4)), ("payload_inertia", slice(4, 10))):
        if name in log and log[name].ndim == 2 and log[name].shape[1] == cols.stop - cols.start:
            out[:, cols] = log[name]
    return out


def from_columns(row: Array) -> Payload:
    """The :class:`~kinergy.model.robot.Payload` of one row of :func:`payload_columns`."""
    row = np.asarray(row, dtype=float)
    return Payload(mass=float(row[0]), com=row[1:4], inertia=row[4:10][_UR_TO_KINERGY])


def logged_loads(log: Log) -> tuple[tuple[Payload | None, ...], NDArray[np.intp]] | None:
    """The payloads ``log`` carries and each sample's index into them (for
    :func:`kinergy.predict.drive_by_payload`), or None when it logs none; a logged mass of 0 is
    no payload (None).

    Raises
    ------
    KinergyError
        Columns that hold no load (a negative mass, moments of inertia that no body has),
        naming the log.
    """
    cols = payload_columns(log)
    if cols is None:
        return None
    unique, index = np.unique(cols, axis=0, return_inverse=True)
    try:
        loads = tuple(
            None if row[0] == 0.0 and not row[1:].any() else from_columns(row) for row in unique
        )
    except KinergyError as exc:
        raise KinergyError(
            f"{log.path}: the controller's payload columns hold no load: {exc}"
        ) from None
    return loads, np.asarray(index, dtype=np.intp).reshape(-1)


def with_logged(robot: Robot, load: Array | None) -> Robot:
    """``robot`` carrying the logged payload ``load`` (columns of :func:`payload_columns`; a
    mass of 0 is none), or ``robot`` itself when ``load`` is None (the log logs no payload)."""
    if load is None:
        return robot
    return robot.with_payload(from_columns(load) if np.any(load) else None)


def describe(payload: Payload | None) -> str:
    """``1.07 kg at [0, 0, 0.058] m`` (``no payload`` for None)."""
    if payload is None:
        return "no payload"
    where = ", ".join(f"{c:.4g}" for c in payload.com)
    return f"{payload.mass:.4g} kg at [{where}] m"


#: poses (per robot, seeded) the holding torque of a logged payload is checked at
_POSES = 64


def _poses(robot: Robot) -> Array:
    """Seeded joint angles within the limits (at most +-pi), plus the home pose q = 0 (a UR arm
    stretched out horizontally): where a payload's holding torque is judged."""
    lo = np.array([max(j.limits.position[0], -np.pi) for j in robot.joints])
    hi = np.array([min(j.limits.position[1], np.pi) for j in robot.joints])
    rng = np.random.default_rng(0)
    inside = lo + rng.random((_POSES, robot.n)) * (hi - lo)
    home = np.clip(np.zeros(robot.n), lo, hi)
    return np.vstack([home, inside])


def payload_problem(robot: Robot, loads: Sequence[Payload]) -> str:
    """What makes one of the logged payloads ``loads`` no load ``robot`` carries, or "": a
    centre of gravity farther than :data:`~kinergy.model.robot.PAYLOAD_REACH` from the flange
    (mm logged as m?), or a mass whose holding torque alone (at the worst of a few poses within
    the limits, the arm stretched out among them) exceeds a joint's torque limit where the arm
    without it stays within: another robot's log, or another unit."""
    poses = _poses(robot)
    bare = np.abs(gravity_torque(robot.with_payload(None), poses))
    limits = np.array([j.limits.torque for j in robot.joints])
    for load in loads:
        reach = float(np.linalg.norm(load.com))
        if reach > PAYLOAD_REACH:
            return (
                f"payload_cog is {reach:.3g} m from the flange, beyond the {PAYLOAD_REACH:g} m a "
                "tool reaches: logged in mm?"
            )
        held = np.abs(gravity_torque(robot.with_payload(load), poses))
        over = (held > limits) & (bare <= limits)
        if over.any():
            pose, j = np.unravel_index(np.argmax(np.where(over, held / limits, 0.0)), over.shape)
            return (
                f"the logged payload of {describe(load)} needs {held[pose, j]:.0f} N m at "
                f"{robot.joints[j].name} to hold still, beyond its {limits[j]:.0f} N m limit: not "
                f"a load {robot.name} carries (another robot's log, or the mass in another unit?)"
            )
    return ""
