"""A log written as a ROS 2 bag (rosbag2 folder, MCAP storage), as UR's ROS 2 driver records one.

The bag holds what :mod:`kinergy.io.rosbag` reads back: one ``sensor_msgs/msg/JointState`` per
sample on ``/joint_states``, its ``header.stamp`` the log's time (``round(t * 1e9)`` ns, the
bag's receive time too), ``position`` ``actual_q`` (rad), ``velocity`` ``actual_qd`` (rad/s)
and ``effort`` the log's motor currents (``actual_current``, A: what UR's driver publishes by
default) or its measured joint torques (``actual_joint_torque`` or
``actual_current_as_torque``, N m), as :class:`~kinergy.io.rosbag.Effort` says; a log's
``robot_mode`` becomes UR's ``/io_and_status_controller/robot_mode`` messages
(``ur_dashboard_msgs/msg/RobotMode``), one at the first sample and one at each change, as the
driver publishes it. Joint names are the robot's, with ``_joint`` for a UR arm (the driver's
``shoulder_pan_joint`` ... ``wrist_3_joint``).

Every other signal of the log (``target_*``, voltages, temperatures) has no place in a
``JointState`` and is left out (:class:`BagWritten` names them). Values are written as float64,
unchanged: reading the bag back gives the log's arrays bit for bit, its time from the first
stamp.

The bag is written in a temporary folder beside the target and renamed into place when it is
complete: an error or Ctrl-C leaves nothing behind; an existing target is never replaced.
"""

from __future__ import annotations

import contextlib
import itertools
import os
import shutil
import tempfile
from collections.abc import Iterable, Iterator, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from kinergy.errors import KinergyError
from kinergy.files import raise_pending
from kinergy.io.log import Log
from kinergy.io.rosbag import DEFAULT_TOPIC, JOINT_STATE, ROBOT_MODE_TOPIC, Effort

if TYPE_CHECKING:  # the ros extra
    from rosbags.typesys.store import Typestore

__all__ = ["TORQUES", "BagWritten", "bag_joint_names", "effort_signal", "write_bag"]

#: the log signals that are measured joint torques, in the order they are taken for ``effort``
TORQUES = ("actual_joint_torque", "actual_current_as_torque")
_ROBOT_MODE = "ur_dashboard_msgs/msg/RobotMode"
#: the signals a JointState carries, besides the effort
_MOTION = ("actual_q", "actual_qd")


@dataclass(frozen=True)
class BagWritten:
    """What :func:`write_bag` wrote.

    Attributes
    ----------
    path : Path
        The bag folder.
    messages : int
        ``JointState`` messages (one per sample).
    effort : str or None
        The log signal written as ``effort`` (None: none).
    left_out : tuple of str
        The log's signals the bag has no field for.
    """

    path: Path
    messages: int
    effort: str | None
    left_out: tuple[str, ...]


def bag_joint_names(joints: Sequence[str]) -> tuple[str, ...]:
    """The names a bag gives the robot's ``joints``: UR's driver's (``elbow_joint``) for a UR
    arm, the robot's own otherwise."""
    from kinergy.io.rosbag import UR_JOINTS

    if tuple(j.removesuffix("_joint") for j in joints) == UR_JOINTS:
        return tuple(j.removesuffix("_joint") + "_joint" for j in joints)
    return tuple(joints)


def effort_signal(signals: Iterable[str], effort: Effort | None, where: str) -> str | None:
    """The log signal to write as ``effort``: ``actual_current`` for :attr:`Effort.CURRENT`,
    the first of :data:`TORQUES` present for :attr:`Effort.TORQUE`; with ``effort`` None the
    currents where the log has them, else its torques, else None.

    Raises
    ------
    KinergyError
        The asked-for kind is not in the log (naming what it has).
    """
    have = set(signals)
    torque = next((s for s in TORQUES if s in have), None)
    if effort is None:
        return "actual_current" if "actual_current" in have else torque
    wanted = "actual_current" if effort is Effort.CURRENT else torque
    if wanted is None or wanted not in have:
        names = "actual_current" if effort is Effort.CURRENT else " or ".join(TORQUES)
        raise KinergyError(
            f"{where}: --effort {effort.value}: the log has no {names}; it has "
            f"{', '.join(sorted(have)) or 'no signal'}"
        )
    return wanted


def _typestore() -> Typestore:
    """ROS 2's message types plus UR's ``ur_dashboard_msgs/msg/RobotMode``."""
    from rosbags.typesys import Stores, get_types_from_msg, get_typestore  # the ros extra

    store = get_typestore(Stores.LATEST)
    store.register(get_types_from_msg("int8 RUNNING=7\nint8 mode\n", _ROBOT_MODE))
    return store


def _stamps(t: np.ndarray, where: str, previous: int) -> np.ndarray:
    """The time stamps ``t`` (s) as integer ns, checked: not negative, strictly increasing."""
    ns = np.round(np.asarray(t, dtype=float) * 1e9)
    if ns.size and (ns[0] < 0 or not np.all(ns < 2.0**63)):
        raise KinergyError(f"{where}: time {t[0]} s cannot be a ROS stamp (0 to 2^63 ns)")
    stamps = ns.astype(np.int64)
    steps = np.diff(np.concatenate([[previous], stamps]))
    if np.any(steps <= 0):
        k = int(np.flatnonzero(steps <= 0)[0])
        raise KinergyError(
            f"{where}: time {t[k]!r} s is not after the sample before to the nanosecond; "
            "a bag's stamps must increase"
        )
    return stamps


def write_bag(
    path: str | os.PathLike[str],
    chunks: Iterable[Log],
    joints: Sequence[str],
    *,
    effort: Effort | None = None,
    topic: str = DEFAULT_TOPIC,
) -> BagWritten:
    """Write the log in ``chunks`` as a rosbag2 folder with MCAP storage at ``path``.

    Parameters
    ----------
    path : path
        The bag folder to create; refused when it exists.
    chunks : iterable of Log
        The log's chunks in time order (:func:`kinergy.io.formats.iter_log`), with ``actual_q``.
    joints : sequence of str
        The robot's joint names, in the log's joint order (:func:`bag_joint_names` spells them).
    effort : Effort, optional
        What ``effort`` holds (:func:`effort_signal`).
    topic : str
        The ``JointState`` topic.

    Raises
    ------
    KinergyError
        ``path`` exists or its folder does not; a log without ``actual_q``, with another joint
        count, with stamps that do not increase in ns; the ``ros`` extra missing.
    """
    target = Path(path)
    if target.exists() or target.is_symlink():
        raise KinergyError(f"{target}: exists; kinergy never replaces it: give a new name")
    if not target.parent.is_dir():
        raise KinergyError(f"{target}: no such folder {target.parent}")
    try:
        from rosbags.rosbag2 import StoragePlugin, Writer  # the ros extra
    except ImportError:
        raise KinergyError(
            f"{target}: writing ROS 2 bags needs the ros extra: pip install 'kinergy[ros]'"
        ) from None
    building = Path(tempfile.mkdtemp(prefix=f".{target.name}.", dir=target.parent))
    try:
        with Writer(building / target.name, version=9, storage_plugin=StoragePlugin.MCAP) as w:
            written = _write(w, iter(chunks), bag_joint_names(joints), effort, topic)
        raise_pending()
        if target.exists() or target.is_symlink():  # appeared while the bag was written
            raise KinergyError(f"{target}: exists; kinergy never replaces it: give a new name")
        os.replace(building / target.name, target)
    finally:
        with contextlib.suppress(OSError):
            shutil.rmtree(building)
    return BagWritten(target, *written)


def _write(
    writer: Any,
    chunks: Iterator[Log],
    names: tuple[str, ...],
    effort: Effort | None,
    topic: str,
) -> tuple[int, str | None, tuple[str, ...]]:
    """Each sample of ``chunks`` as a ``JointState`` (module docstring); the messages, the
    effort's signal and the signals left out."""
    store = _typestore()
    state = store.types[JOINT_STATE]
    header, stamp = store.types["std_msgs/msg/Header"], store.types["builtin_interfaces/msg/Time"]
    first: Log | None = next(chunks, None)
    if first is None or len(first) == 0:
        raise KinergyError("the log has no samples")
    first.require("actual_q", purpose="a bag")
    where = first.path
    which = effort_signal(first.signals, effort, where)
    fields = [s for s in _MOTION if s in first.signals] + ([which] if which else [])
    left_out = tuple(s for s in first.signals if s not in fields and s != "robot_mode")
    conn = writer.add_connection(topic, state.__msgtype__, typestore=store)
    mode_type = store.types[_ROBOT_MODE]
    mode_conn = None
    if "robot_mode" in first.signals:
        mode_conn = writer.add_connection(ROBOT_MODE_TOPIC, mode_type.__msgtype__, typestore=store)
    empty = np.empty(0)
    count, previous, mode = 0, -1, None
    for chunk in itertools.chain([first], chunks):
        values = [np.ascontiguousarray(chunk[s], dtype=np.float64) for s in fields]
        if any(v.ndim != 2 or v.shape[1] != len(names) for v in values):
            raise KinergyError(
                f"{where}: {len(names)} joints expected ({', '.join(names)}); the log has "
                f"{values[0].shape[1] if values[0].ndim == 2 else 1}"
            )
        ns = _stamps(chunk.t, where, previous)
        modes = chunk["robot_mode"] if mode_conn is not None else None
        for k, when in enumerate(ns.tolist()):
            if modes is not None and modes[k] != mode:
                mode = modes[k]
                raw = store.serialize_cdr(mode_type(mode=int(mode)), mode_type.__msgtype__)
                writer.write(mode_conn, when, raw)
            columns = {"actual_q": empty, "actual_qd": empty, "effort": empty}
            for s, v in zip(fields, values, strict=True):
                columns["effort" if s == which else s] = v[k]
            msg = state(
                header(stamp(when // 1_000_000_000, when % 1_000_000_000), ""),
                list(names),
                columns["actual_q"],
                columns["actual_qd"],
                columns["effort"],
            )
            writer.write(conn, when, store.serialize_cdr(msg, state.__msgtype__))
        count += len(ns)
        previous = int(ns[-1])
        raise_pending()
    return count, which, left_out
