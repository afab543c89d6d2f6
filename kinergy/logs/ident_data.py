"""The prepared samples of one log that identification folds over (:class:`IdentData`), and the
signals they come from.

Arrays are (N, n) unless noted; :func:`ident_data` builds one from a uniform log and its
commanded and real motions (:mod:`kinergy.logs.prepare` says how those are obtained).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, fields

import numpy as np

from kinergy.arrays import Array
from kinergy.io.log import Log

__all__ = [
    "JOINT_SIGNALS",
    "MEASURED_TORQUE",
    "SAMPLE_FIELDS",
    "IdentData",
    "Motion3",
    "ident_data",
]


@dataclass(frozen=True, eq=False)
class IdentData:
    """One log, ready for identification. Arrays are (N, n) unless noted.

    Attributes
    ----------
    path : str
    t : ndarray, shape (N,)
        Uniform time stamps, s.
    q_cmd, qd_cmd, qdd_cmd :
        The motion ``target_moment`` refers to (commanded; measured when the log has no target).
    q, qd, qdd :
        The real motion (commanded delayed by ``lag``, or the filtered measured motion).
    tau_ref : ndarray or None
        ``target_moment``, N m.
    current : ndarray or None
        ``actual_current``, A.
    torque : ndarray or None
        Measured joint torques, N m (arms with torque sensors).
    lag : float
        Estimated lag of the real motion behind the commanded one, s.
    source : str
        How the real motion was obtained: ``"delayed target"`` or ``"filtered actual"``.
    temperature : ndarray or None
        ``joint_temperatures``, deg C.
    voltage : ndarray or None
        ``actual_joint_voltage``, V (as the controller logs it).
    supply_voltage, supply_current : ndarray, shape (N,), or None
        ``actual_robot_voltage`` (V) and ``actual_robot_current`` (A): the arm's supply.
    """

    path: str
    t: Array
    q_cmd: Array
    qd_cmd: Array
    qdd_cmd: Array
    q: Array
    qd: Array
    qdd: Array
    tau_ref: Array | None
    current: Array | None
    torque: Array | None
    lag: float
    source: str
    temperature: Array | None = None
    voltage: Array | None = None
    supply_voltage: Array | None = None
    supply_current: Array | None = None

    def __len__(self) -> int:
        return int(self.t.size)

    @property
    def dt(self) -> float:
        return float(self.t[1] - self.t[0])

    @classmethod
    def joined(cls, parts: Sequence[IdentData]) -> IdentData:
        """Samples of ``parts`` one after the other (a field is None when any part lacks it);
        the last part's path, lag and source."""
        if len(parts) == 1:
            return parts[0]
        joined: dict[str, Array | None] = {}
        for name in SAMPLE_FIELDS:
            values = [getattr(p, name) for p in parts]
            joined[name] = None if any(v is None for v in values) else np.concatenate(values)
        last = parts[-1]
        return cls(path=last.path, lag=last.lag, source=last.source, **joined)  # type: ignore[arg-type]

    def sliced(self, start: int, stop: int) -> IdentData:
        """Samples ``start:stop`` (for hold-out splits)."""

        def cut(x: Array | None) -> Array | None:
            return None if x is None else x[start:stop]

        return IdentData(
            self.path,
            self.t[start:stop],
            self.q_cmd[start:stop],
            self.qd_cmd[start:stop],
            self.qdd_cmd[start:stop],
            self.q[start:stop],
            self.qd[start:stop],
            self.qdd[start:stop],
            cut(self.tau_ref),
            cut(self.current),
            cut(self.torque),
            self.lag,
            self.source,
            cut(self.temperature),
            cut(self.voltage),
            cut(self.supply_voltage),
            cut(self.supply_current),
        )


#: the log signal of measured joint torques, N m (RTDE-style name, ``actual_joint_torque_k``)
MEASURED_TORQUE = "actual_joint_torque"

#: (N, n) signals whose joint count must match the robot's
JOINT_SIGNALS = (
    "target_q",
    "target_qd",
    "target_qdd",
    "actual_q",
    "actual_qd",
    "actual_qdd",
    "target_moment",
    "actual_current",
    MEASURED_TORQUE,
    "joint_temperatures",
    "actual_joint_voltage",
)


#: (q, qd, qdd), each (N, n)
Motion3 = tuple[Array, Array, Array]


#: IdentData fields that hold samples, (N, ...) each
SAMPLE_FIELDS = tuple(f.name for f in fields(IdentData) if f.name not in ("path", "lag", "source"))


def ident_data(
    log: Log,
    commanded: Motion3,
    real: Motion3,
    how: tuple[float, str],
    *,
    torque: Array | None = None,
) -> IdentData:
    """:class:`IdentData` of a uniform ``log`` with its ``commanded`` and ``real`` motions (each
    (q, qd, qdd)), ``how`` = (lag in s, how the real motion was obtained); measured joint
    torques from ``torque`` or else the log's :data:`MEASURED_TORQUE`."""
    if torque is None and MEASURED_TORQUE in log:  # arms with joint torque sensors
        torque = np.asarray(log[MEASURED_TORQUE], dtype=float)
    q_cmd, qd_cmd, qdd_cmd = (np.asarray(x, dtype=float) for x in commanded)
    q, qd, qdd = (np.asarray(x, dtype=float) for x in real)
    return IdentData(
        path=log.path,
        t=log.t,
        q_cmd=q_cmd,
        qd_cmd=qd_cmd,
        qdd_cmd=qdd_cmd,
        q=q,
        qd=qd,
        qdd=qdd,
        tau_ref=log["target_moment"] if "target_moment" in log else None,
        current=log["actual_current"] if "actual_current" in log else None,
        torque=torque,
        lag=how[0],
        source=how[1],
        temperature=_signal(log, "joint_temperatures"),
        voltage=_signal(log, "actual_joint_voltage"),
        supply_voltage=_signal(log, "actual_robot_voltage"),
        supply_current=_signal(log, "actual_robot_current"),
    )


def _signal(log: Log, name: str) -> Array | None:
    """A measured signal of the log, or None when it lacks it."""
    return np.asarray(log[name], dtype=float) if name in log else None
