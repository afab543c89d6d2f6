"""ROS 2 bags (rosbag2) as logs: ``sensor_msgs/msg/JointState`` read with the ``rosbags`` library.

A bag is a rosbag2 folder (``metadata.yaml`` beside its ``.mcap`` or ``.db3`` files; its
``metadata.yaml`` names it too) or one storage file (``.mcap`` or ``.db3``); the ``rosbags`` library (pure Python, the ``ros`` extra)
reads MCAP and SQLite3 storage without a ROS install. From the ``JointState`` messages on
``/joint_states`` (another topic by :class:`BagOptions`):

- each message's ``header.stamp`` is the time stamp, strictly increasing, in s from the first
  message's (taken in integer nanoseconds: stamps since 1970, as drivers write them, would lose
  a quarter of a microsecond as seconds in a float, and the results would then depend on the
  clock's origin);
- its joints are matched to the robot's by name, in any order and per message: a robot joint
  ``elbow`` is the bag's ``elbow`` or ``elbow_joint`` (UR's driver names ``shoulder_pan_joint``
  ... ``wrist_3_joint``; a robot file that says ``elbow_joint`` matches ``elbow`` too), with one
  prefix common to all joints allowed (a driver's ``tf_prefix``, Franka's ``panda_``); joints the
  robot does not have (a gripper) are left out;
- ``position`` is ``actual_q`` (rad), ``velocity`` ``actual_qd`` (rad/s), and ``effort``
  ``actual_current`` (motor currents, A) or ``actual_joint_torque`` (N m) as
  :class:`BagOptions` ``effort`` says (:class:`Effort`; default :func:`default_effort`).

What UR's ROS 2 driver (``ur_robot_driver``) puts in ``effort``: the motor currents, RTDE's
``actual_current``, in every release of the Humble, Jazzy and Kilted distributions and of Rolling
up to 7.0.0. A later change on its main (Rolling) branch adds the hardware parameter
``use_currents_as_efforts``; where it is false (Rolling's default from that change on) the driver
reports RTDE's ``actual_current_as_torque``, joint torques in N m, which the controller provides
from PolyScope 5.23.0 (e-Series) / 10.11.0 (PolyScope X) on. The backport to the stable
distributions keeps the currents by default. So the default for a UR robot is
:attr:`Effort.CURRENT`; :func:`effort_scale` tells from the data which one a bag holds.

UR's driver publishes ``/io_and_status_controller/robot_mode``
(``ur_dashboard_msgs/msg/RobotMode``, latched, on change) too: where a bag has it, it becomes the
log's ``robot_mode`` (RTDE's codes; 7 is RUNNING), held from each message to the next, the first
value also before it; identification then keeps the samples where the robot runs, as for an
RTDE log. The driver's other topics are not read (docs/ROSBAGS.md says why).

Every problem is one line naming the bag: not a bag, unreadable, unknown storage, no such topic
(naming the topics it has), joints missing (naming them and the bag's joints), stamps not
increasing (``repair`` drops those messages instead, noted), a bag still being written (a folder
without ``metadata.yaml``; an MCAP file without its closing summary and footer).

The bag is read message by message into chunks of ``rows`` samples: memory does not grow with it.
"""

from __future__ import annotations

import datetime
import enum
import functools
import os
from collections.abc import Iterable, Iterator, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from kinergy.arrays import Array
from kinergy.drives.electrics import torque_constants
from kinergy.errors import KinergyError
from kinergy.io.formats import LogFormat, register
from kinergy.io.log import Log

if TYPE_CHECKING:  # the ros extra
    from rosbags.interfaces import Connection
    from rosbags.rosbag2 import Reader
    from rosbags.typesys.store import Typestore

    from kinergy.model.robot import Robot

__all__ = [
    "DEFAULT_TOPIC",
    "JOINT_STATE",
    "ROBOT_MODE_TOPIC",
    "ROSBAG",
    "UR_JOINTS",
    "BagOptions",
    "Effort",
    "EffortScale",
    "bag_options",
    "default_effort",
    "effort_scale",
    "first_stamp",
    "is_bag",
    "match_joints",
]

#: the topic UR's driver (and ros2_control's joint_state_broadcaster) publishes joint states on
DEFAULT_TOPIC = "/joint_states"
#: the message type read
JOINT_STATE = "sensor_msgs/msg/JointState"
#: UR's driver: the robot mode (RTDE's codes), latched, published when it changes
ROBOT_MODE_TOPIC = "/io_and_status_controller/robot_mode"
_ROBOT_MODE = "ur_dashboard_msgs/msg/RobotMode"
#: kinergy's joint names of every UR arm (the driver's are these with ``_joint``)
UR_JOINTS = ("shoulder_pan", "shoulder_lift", "elbow", "wrist_1", "wrist_2", "wrist_3")

_MCAP_MAGIC = b"\x89MCAP0\r\n"
_SQLITE_MAGIC = b"SQLite format 3\x00"
#: storage file suffixes rosbag2 writes, by storage
_SUFFIXES = {".mcap": "mcap", ".db3": "sqlite3"}
#: distinct joint orders remembered while reading (each message may order its joints anew)
_ORDERS = 256


class Effort(enum.Enum):
    """What a bag's ``JointState.effort`` holds."""

    #: motor currents, A (RTDE ``actual_current``): UR's driver unless told otherwise
    CURRENT = "current"
    #: joint torques, N m (``actual_joint_torque``): ros2_control's convention
    TORQUE = "torque"

    @property
    def signal(self) -> str:
        """The log signal the effort becomes."""
        return "actual_current" if self is Effort.CURRENT else "actual_joint_torque"


@dataclass(frozen=True)
class BagOptions:
    """How to read a ROS 2 bag.

    Attributes
    ----------
    topic : str
        The ``sensor_msgs/msg/JointState`` topic; a name without the leading ``/`` is taken as
        absolute (``joint_states`` is ``/joint_states``).
    effort : Effort or None
        What ``effort`` holds; None: :func:`default_effort` of the robot's joints.
    """

    topic: str = DEFAULT_TOPIC
    effort: Effort | None = None

    def __post_init__(self) -> None:
        topic = self.topic.strip()
        if not topic.strip("/") or any(c.isspace() for c in topic):
            raise KinergyError(f"--topic: {self.topic!r} is not a ROS topic name")
        object.__setattr__(self, "topic", topic if topic.startswith("/") else "/" + topic)
        if self.effort is not None and not isinstance(self.effort, Effort):
            raise KinergyError(f"--effort: {self.effort!r} is not one of current, torque")


def bag_options(topic: str | None = None, effort: str | Effort | None = None) -> BagOptions | None:
    """The options ``--topic`` and ``--effort`` give (None when neither is given).

    Raises
    ------
    KinergyError
        A topic that is no topic name, an effort other than ``current`` or ``torque``.
    """
    if topic is None and effort is None:
        return None
    if isinstance(effort, str):
        try:
            effort = Effort(effort.strip().lower())
        except ValueError:
            raise KinergyError(f"--effort: {effort!r} is not one of current, torque") from None
    return BagOptions(DEFAULT_TOPIC if topic is None else topic, effort)


def _base(name: str) -> str:
    return name.removesuffix("_joint")


def default_effort(joints: Sequence[str]) -> Effort:
    """What ``effort`` holds unless told: motor currents for a UR arm (its joints are
    :data:`UR_JOINTS`, with or without ``_joint``), as UR's ROS 2 driver publishes them by default
    (module docstring); joint torques, ros2_control's convention, for any other robot."""
    return Effort.CURRENT if tuple(_base(j) for j in joints) == UR_JOINTS else Effort.TORQUE


def _spellings(joint: str) -> tuple[str, str]:
    base = _base(joint)
    return base, base + "_joint"


def _match(names: Sequence[str], joints: Sequence[str], prefix: str) -> list[int] | None:
    """The index in ``names`` of each joint, spelled ``prefix + joint`` with or without
    ``_joint``; None when a joint is not there exactly once."""
    index: list[int] = []
    for joint in joints:
        hits = [
            k for k, name in enumerate(names) if name in {prefix + s for s in _spellings(joint)}
        ]
        if len(hits) != 1:
            return None
        index.append(hits[0])
    return index


def match_joints(names: Sequence[str], joints: Sequence[str], where: str) -> tuple[list[int], str]:
    """Where each of the robot's ``joints`` is among a bag's joint ``names``.

    A joint ``elbow`` (or ``elbow_joint``) is the name ``elbow`` or ``elbow_joint``, in any
    order, others ignored; when no joint matches as written, one prefix common to all joints is
    tried (a driver's ``tf_prefix``).

    Returns
    -------
    index : list of int
        ``names[index[k]]`` is joint ``k``.
    prefix : str
        The prefix found ('' when the names match as written).

    Raises
    ------
    KinergyError
        A joint missing (naming them and the bag's joints), or the joints of several arms.
    """
    found = _match(names, joints, "")
    if found is not None:
        return found, ""
    prefixes = sorted(
        {
            name[: -len(s)]
            for name in names
            for s in _spellings(joints[0])
            if name.endswith(s) and len(name) > len(s)
        }
    )
    fits = [(p, m) for p in prefixes if (m := _match(names, joints, p)) is not None]
    if len(fits) == 1:
        return fits[0][1], fits[0][0]
    if len(fits) > 1:
        raise KinergyError(
            f"{where}: the bag has the joints of {len(fits)} arms (prefixes "
            f"{', '.join(repr(p) for p, _ in fits)}); record one arm's joint states per bag"
        )
    twice = [j for j in joints if sum(n in _spellings(j) for n in names) > 1]
    if twice:
        spelled = [n for n in names if n in _spellings(twice[0])]
        raise KinergyError(
            f"{where}: joint {twice[0]} is in the bag twice ({', '.join(spelled)}): which one "
            "is the robot's? record one arm's joint states under one name each"
        )
    missing = [j for j in joints if not any(n in _spellings(j) for n in names)]
    what = ", ".join(missing) if missing else ", ".join(joints)
    raise KinergyError(
        f"{where}: the robot's joint(s) {what} not in the bag (looked for NAME or NAME_joint); "
        f"the bag's joints: {', '.join(names) or 'none'}"
    )


def _magic(path: Path) -> bytes:
    try:
        with path.open("rb") as fh:
            return fh.read(16)
    except OSError:
        return b""


def is_bag(path: Path, head: str = "") -> bool:
    """Whether ``path`` is a ROS 2 bag: a folder with ``metadata.yaml`` or storage files, its
    ``metadata.yaml``, or an ``.mcap`` or ``.db3`` file (or one that starts as MCAP or SQLite
    does)."""
    if path.name == "metadata.yaml":
        return True
    if path.is_dir():
        return (path / "metadata.yaml").is_file() or any(
            p.suffix in _SUFFIXES for p in path.iterdir()
        )
    if path.suffix in _SUFFIXES:
        return True
    magic = _magic(path)
    return magic.startswith(_MCAP_MAGIC) or magic.startswith(_SQLITE_MAGIC)


def _reader_error(path: Path, text: str) -> KinergyError:
    """The one line for what ``rosbags`` said about a bag it could not open."""
    lowered = text.lower()
    if "storage plugin" in lowered:
        return KinergyError(f"{path}: unknown bag storage ({text}); kinergy reads mcap and sqlite3")
    if "end magic" in lowered or "truncated" in lowered or "footer" in lowered:
        return KinergyError(
            f"{path}: the MCAP file ends without its summary and footer: still being written, "
            "or its recording was cut short (a recorder writes them when it stops)"
        )
    if "file magic" in lowered or "profile" in lowered:
        return KinergyError(f"{path}: not a ROS 2 MCAP bag ({text})")
    if "database" in lowered:
        return KinergyError(f"{path}: not a rosbag2 SQLite3 bag ({text})")
    return KinergyError(f"{path}: cannot read the ROS 2 bag ({text})")


def _open(path: Path) -> Reader:
    """An open ``rosbags`` reader of the bag at ``path``."""
    try:
        from rosbags.rosbag2 import Reader  # the ros extra
    except ImportError:
        raise KinergyError(
            f"{path}: reading ROS 2 bags needs the ros extra: pip install 'kinergy[ros]'"
        ) from None
    if path.is_dir() and not (path / "metadata.yaml").is_file():
        raise KinergyError(
            f"{path}: a bag folder without metadata.yaml: still being written, or its recording "
            "was cut short (rosbag2 writes metadata.yaml when it stops; `ros2 bag reindex` "
            "rebuilds it)"
        )
    if not path.is_dir() and path.suffix not in _SUFFIXES:
        kind = "MCAP" if _magic(path).startswith(_MCAP_MAGIC) else "SQLite3"
        suffix = ".mcap" if kind == "MCAP" else ".db3"
        raise KinergyError(f"{path}: an {kind} bag file must be named *{suffix} to be read")
    try:
        reader = Reader(path)
        reader.open()
    except KinergyError:
        raise
    except Exception as exc:  # rosbags reports a bad bag with several exception types
        raise _reader_error(path, str(exc) or type(exc).__name__) from None
    return reader


@functools.cache
def _typestore() -> Typestore:
    """The message types of the latest ROS 2 release (``JointState`` is the same in every
    one)."""
    from rosbags.typesys import Stores, get_typestore  # the ros extra

    return get_typestore(Stores.LATEST)


def _topic(reader: Reader, path: Path, topic: str) -> list[Connection]:
    """The connections of ``topic``, checked: present, ``JointState``, with messages."""
    topics = reader.topics
    if topic not in topics:
        states = sorted(t for t, info in topics.items() if info.msgtype == JOINT_STATE)
        have = ", ".join(sorted(topics)[:20]) + (" ..." if len(topics) > 20 else "")
        hint = f"; its JointState topics: {', '.join(states)}" if states else ""
        raise KinergyError(
            f"{path}: no topic {topic} in the bag{hint}; its topics: {have or 'none'}"
        )
    info = topics[topic]
    if info.msgtype != JOINT_STATE:
        raise KinergyError(f"{path}: topic {topic} holds {info.msgtype}, not {JOINT_STATE}")
    if info.msgcount < 2:
        raise KinergyError(f"{path}: topic {topic} has {info.msgcount} message(s); need 2 or more")
    return list(info.connections)


def first_stamp(path: str | os.PathLike[str], bag: BagOptions | None = None) -> int:
    """The header stamp (ns) of the first ``JointState`` message of the bag at ``path`` (on
    ``bag``'s topic): what a bag read as a log takes as time 0 s."""
    path = Path(path)
    options = bag or BagOptions()
    reader = _open(path.parent if path.name == "metadata.yaml" else path)
    try:
        conns = _topic(reader, path, options.topic)
        for conn, _, raw in reader.messages(conns):
            msg: Any = _typestore().deserialize_cdr(raw, conn.msgtype)
            return int(msg.header.stamp.sec) * 1_000_000_000 + int(msg.header.stamp.nanosec)
    finally:
        reader.close()
    raise KinergyError(f"{path}: no message on {options.topic}")  # _topic saw messages


def _robot_modes(reader: Reader) -> tuple[NDArray[np.int64], NDArray[np.float64]] | None:
    """UR's driver's robot mode messages: their bag times (ns) and modes; None without any."""
    conns = [c for c in reader.connections if c.topic == ROBOT_MODE_TOPIC]
    if not conns or any(c.msgtype != _ROBOT_MODE for c in conns):
        return None
    times, modes = [], []
    for _, stamp, raw in reader.messages(conns):
        # CDR: a 4-byte encapsulation header, then the message's one field, ``int8 mode``
        if len(raw) >= 5:
            times.append(stamp)
            modes.append(float(np.frombuffer(raw, dtype=np.int8, count=1, offset=4)[0]))
    if not times:
        return None
    return np.asarray(times, dtype=np.int64), np.asarray(modes, dtype=float)


class _Chunks:
    """Fills chunk buffers from ``JointState`` messages and hands them out as :class:`Log`,
    with the robot mode (``modes``: bag times in ns and modes) held at their stamps."""

    def __init__(
        self,
        path: Path,
        n: int,
        signals: Sequence[str],
        rows: int,
        modes: tuple[NDArray[np.int64], Array] | None,
    ):
        self.path, self.rows, self.modes = path, rows, modes
        self.ns = np.empty(rows, dtype=np.int64)
        self.values = {name: np.empty((rows, n)) for name in signals}
        self.count = 0
        self.notes: list[str] = []
        self.origin: int | None = None  # the first sample's stamp, ns: time 0

    def add(self, ns: int, arrays: dict[str, Array]) -> Log | None:
        """Add one sample; the chunk when it is full."""
        if self.origin is None:
            self.origin = ns
            when = datetime.datetime.fromtimestamp(ns // 1_000_000_000, datetime.UTC)
            self.notes.append(
                f"{self.path}: time 0 s is the first message's header stamp ({ns} ns, "
                f"{when:%Y-%m-%d %H:%M:%S} UTC)"
            )
        k = self.count
        self.ns[k] = ns
        for name, buffer in self.values.items():
            buffer[k] = arrays[name]
        self.count = k + 1
        return self.flush() if self.count == self.rows else None

    def flush(self) -> Log | None:
        """The samples so far as a chunk (None when there are none)."""
        k, self.count = self.count, 0
        if k == 0:
            return None
        ns = self.ns[:k].copy()
        signals = {name: buffer[:k].copy() for name, buffer in self.values.items()}
        if self.modes is not None:
            at = np.searchsorted(self.modes[0], ns, side="right") - 1
            signals["robot_mode"] = self.modes[1][np.maximum(at, 0)]
        notes, self.notes = self.notes, []
        assert self.origin is not None
        return Log(str(self.path), (ns - self.origin) / 1e9, signals, notes)


def _bag_chunks(
    path: Path,
    *,
    columns: str | None,
    repair: bool,
    select: Sequence[str] | None,
    rows: int,
    joints: tuple[str, ...] | None,
    bag: BagOptions | None,
) -> Iterator[Log]:
    """The :class:`~kinergy.io.formats.LogFormat` reader of ROS 2 bags (module docstring)."""
    if columns is not None:
        raise KinergyError(f"{path}: a ROS 2 bag names its fields; --columns is for text logs")
    if not joints:
        raise KinergyError(
            f"{path}: a ROS 2 bag is read with the robot's joint names (joints=robot.joint_names)"
        )
    options = bag or BagOptions()
    effort = options.effort or default_effort(joints)
    reader = _open(path.parent if path.name == "metadata.yaml" else path)
    try:
        yield from _read(reader, path, joints, options.topic, effort, repair, select, rows)
    finally:
        reader.close()


def _read(
    reader: Reader,
    path: Path,
    joints: tuple[str, ...],
    topic: str,
    effort: Effort,
    repair: bool,
    select: Sequence[str] | None,
    rows: int,
) -> Iterator[Log]:
    conns = _topic(reader, path, topic)
    modes = _robot_modes(reader)
    store = _typestore()
    where = f"{path}: {topic}"
    fields = {"actual_q": "position", "actual_qd": "velocity", effort.signal: "effort"}
    orders: dict[tuple[str, ...], NDArray[np.intp]] = {}
    chunks: _Chunks | None = None
    pending: Log | None = None  # a full chunk, held back until the next sample: the last one
    prefix, previous, dropped, count = "", -1, 0, 0
    for conn, _, raw in reader.messages(conns):
        count += 1
        try:
            msg: Any = store.deserialize_cdr(raw, conn.msgtype)
        except Exception as exc:  # a corrupt message: rosbags raises several types
            raise KinergyError(f"{where}: message {count} cannot be decoded ({exc})") from None
        names = tuple(msg.name)
        order = orders.get(names)
        if order is None:
            if chunks is None:
                index, prefix = match_joints(names, joints, where)
            else:
                found = _match(names, joints, prefix)
                if found is None:
                    index, _ = match_joints(
                        names, [prefix + j for j in joints], f"{where}: message {count}"
                    )
                else:
                    index = found
            if len(orders) >= _ORDERS:
                orders.clear()
            order = orders[names] = np.asarray(index, dtype=np.intp)
        stamp = int(msg.header.stamp.sec) * 1_000_000_000 + int(msg.header.stamp.nanosec)
        if chunks is None:
            have = [s for s, f in fields.items() if len(getattr(msg, f)) > 0]
            chunks = _start(path, where, len(joints), have, select, rows, modes)
            chunks.notes += _first_notes(path, names, joints, order, prefix, effort, have)
        if stamp <= previous:
            if not repair:
                raise KinergyError(
                    f"{where}: message {count}: header stamp {stamp / 1e9:.9f} s is not after "
                    f"the one before ({previous / 1e9:.9f} s); --repair drops such messages"
                )
            dropped += 1
            continue
        arrays = _values(msg, chunks.values, fields, order, f"{where}: message {count}")
        bad = next((k for k, x in arrays.items() if not np.all(np.isfinite(x))), None)
        if bad is not None:
            if not repair:
                j = int(np.flatnonzero(~np.isfinite(arrays[bad]))[0])
                raise KinergyError(
                    f"{where}: message {count}: {fields[bad]} of {joints[j]} is "
                    f"{arrays[bad][j]}: not a finite number; --repair drops such messages"
                )
            dropped += 1
            continue
        previous = stamp
        if pending is not None:
            yield pending
        pending = chunks.add(stamp, arrays)
    assert chunks is not None  # _topic saw messages
    if dropped:
        chunks.notes.append(
            f"{where}: {dropped} message(s) whose header stamp was not after the one before, "
            "or with a value that is not a number, dropped (--repair)"
        )
    last = chunks.flush()
    if pending is not None:
        if last is None:
            pending.notes.extend(chunks.notes)
        yield pending
    if last is not None:
        yield last


def _start(
    path: Path,
    where: str,
    n: int,
    have: list[str],
    select: Sequence[str] | None,
    rows: int,
    modes: tuple[NDArray[np.int64], Array] | None,
) -> _Chunks:
    """The chunks of a bag whose first joint state has the signals ``have``: those of
    ``select`` (all when None), ``robot_mode`` only when selected."""
    if "actual_q" not in have:
        raise KinergyError(f"{where}: the joint states have no positions")
    wanted = have if select is None else [s for s in have if s in select]
    if select is not None:
        possible = [*have, *(["robot_mode"] if modes is not None else [])]
        missing = [s for s in select if s not in possible]
        if missing:
            raise KinergyError(
                f"{path}: no field(s) for {', '.join(missing)}; the bag has: {', '.join(possible)}"
            )
        if "robot_mode" not in select:
            modes = None
    return _Chunks(path, n, wanted, rows, modes)


def _values(
    msg: Any,
    signals: Iterable[str],
    fields: dict[str, str],
    order: NDArray[np.intp],
    where: str,
) -> dict[str, Array]:
    """Each signal's values of one joint state, (n,) in the robot's joint order."""
    arrays = {}
    for signal in signals:
        values = np.asarray(getattr(msg, fields[signal]), dtype=float)
        if values.shape != (len(msg.name),):
            raise KinergyError(
                f"{where}: {values.size} {fields[signal]} value(s) for {len(msg.name)} joint names"
            )
        arrays[signal] = values[order]
    return arrays


def _first_notes(
    path: Path,
    names: tuple[str, ...],
    joints: tuple[str, ...],
    order: NDArray[np.intp],
    prefix: str,
    effort: Effort,
    have: Sequence[str],
) -> list[str]:
    """What reading the bag assumed: the effort's meaning, a prefix, joints left out."""
    notes = []
    if effort.signal in have:
        what = "motor currents (A)" if effort is Effort.CURRENT else "joint torques (N m)"
        notes.append(f"{path}: effort read as {what}, {effort.signal} (--effort to change)")
    if prefix:
        notes.append(f"{path}: joints matched with the prefix {prefix!r}")
    extra = [n for k, n in enumerate(names) if k not in set(order.tolist())]
    if extra:
        notes.append(f"{path}: joint(s) {', '.join(extra)} not in the robot: left out")
    return notes


#: ROS 2 bags: rosbag2 folders and ``.mcap`` / ``.db3`` files (the ``ros`` extra)
ROSBAG = register(LogFormat("rosbag", is_bag, _bag_chunks, folders=True, joints=True))


@dataclass(frozen=True)
class EffortScale:
    """How a log's effort compares with the model's gravity torque (:func:`effort_scale`).

    Attributes
    ----------
    torque : float
        Least-squares ``s`` in ``effort ~ s * tau_g``: about 1 if the effort holds joint torques.
    current : float
        Least-squares ``s`` in ``effort ~ s * tau_g / (k_t * N)``: about 1 if it holds motor
        currents.
    effort : Effort
        The reading whose scale is nearer 1 (on a log scale).
    """

    torque: float
    current: float
    effort: Effort


def effort_scale(robot: Robot, log: Log, signal: str | None = None) -> EffortScale:
    """Tell from the data whether a log's effort is motor currents or joint torques.

    The gravity torque of the robot's model along the log's positions, ``tau_g(q)`` (RNEA at
    zero speed and acceleration), carries most of the torque of the joints gravity loads in any
    motion a robot logs. Read as joint torques the effort is about ``tau_g``; read as motor
    currents, about ``tau_g / (k_t N)`` (UR5e eq 17, friction and inertia aside), ten times
    smaller on a UR arm. Both least-squares scales over the joints whose gravity torque is at
    least a fifth of the largest are returned; the one nearer 1 names the effort.

    Parameters
    ----------
    robot : Robot
    log : Log
        With ``actual_q`` (N, n) and the effort signal (N, n).
    signal : str, optional
        The effort's signal (default: ``actual_current`` or ``actual_joint_torque``, whichever
        the log has).

    Raises
    ------
    KinergyError
        The log has no effort, or gravity loads no joint along its positions.
    """
    from kinergy.dynamics.rnea import gravity_torque  # heavy: compiles the dynamics kernels

    if signal is None:
        signal = next((s.signal for s in Effort if s.signal in log), Effort.CURRENT.signal)
    log.require("actual_q", signal, purpose="telling the effort's kind")
    step = max(1, len(log) // 2000)  # 2000 samples are plenty for a scale
    q, effort = log["actual_q"][::step], log[signal][::step]
    tau_g = gravity_torque(robot, q)
    size = np.sqrt(np.mean(tau_g**2, axis=0))
    loaded = size >= 0.2 * size.max()
    if not size.max() > 0:
        raise KinergyError(f"{log.path}: gravity loads no joint along this motion")
    gear = np.array([j.drive.gear_ratio for j in robot.joints])
    fits = []
    for model in (tau_g, tau_g / (torque_constants(robot) * gear)):
        g, e = model[:, loaded], effort[:, loaded]
        fits.append(float(np.sum(g * e) / np.sum(g * g)))
    torque, current = fits
    distance = [abs(np.log(max(abs(s), 1e-12))) for s in fits]
    return EffortScale(
        torque, current, Effort.TORQUE if distance[0] <= distance[1] else Effort.CURRENT
    )
