"""Writing ROS 2 bags for the tests, with the ``rosbags`` library (as a ROS 2 recorder would)."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike

if TYPE_CHECKING:
    from rosbags.typesys.store import Typestore

#: UR's ROS 2 driver's joint names (kinergy's UR joint names with ``_joint``)
UR_DRIVER_JOINTS = (
    "shoulder_pan_joint",
    "shoulder_lift_joint",
    "elbow_joint",
    "wrist_1_joint",
    "wrist_2_joint",
    "wrist_3_joint",
)


def typestore() -> Typestore:
    """ROS 2 Humble's message types plus UR's ``ur_dashboard_msgs/msg/RobotMode``."""
    from rosbags.typesys import Stores, get_types_from_msg, get_typestore

    store = get_typestore(Stores.ROS2_HUMBLE)
    store.register(
        get_types_from_msg("int8 RUNNING=7\nint8 mode\n", "ur_dashboard_msgs/msg/RobotMode")
    )
    return store


def write_bag(
    path: Path,
    t: ArrayLike,
    q: ArrayLike,
    qd: ArrayLike | None = None,
    effort: ArrayLike | None = None,
    *,
    names: Sequence[str] = UR_DRIVER_JOINTS,
    storage: str = "mcap",
    extra: str | None = "finger_joint",
    shuffle: int | None = 0,
    topic: str = "/joint_states",
    stamps_ns: Sequence[int] | None = None,
    robot_modes: Sequence[tuple[int, int]] = (),
    other_topics: Sequence[str] = (),
) -> Path:
    """Write a rosbag2 folder at ``path`` with one ``sensor_msgs/msg/JointState`` per sample.

    ``t`` (s) becomes the bag (receive) times and the header stamps (``round(t * 1e9)`` ns,
    unless ``stamps_ns`` gives them); ``extra`` adds a joint the robot does not have (a gripper, value 0.01); ``shuffle``
    seeds a random order of the joints in each message (None: in order); ``robot_modes`` adds
    ``(bag time ns, mode)`` messages on UR's robot-mode topic; ``other_topics`` adds one
    ``std_msgs/msg/Float64`` message each.
    """
    from rosbags.rosbag2 import Writer
    from rosbags.rosbag2.enums import StoragePlugin

    store = typestore()
    joint_state = store.types["sensor_msgs/msg/JointState"]
    header, stamp = store.types["std_msgs/msg/Header"], store.types["builtin_interfaces/msg/Time"]
    times = np.asarray(t, dtype=float)
    columns = [np.asarray(x, dtype=float) if x is not None else None for x in (q, qd, effort)]
    all_names = np.array([*names, *([extra] if extra else [])])
    rng = np.random.default_rng(shuffle) if shuffle is not None else None
    plugin = StoragePlugin.MCAP if storage == "mcap" else StoragePlugin.SQLITE3
    with Writer(path, version=9, storage_plugin=plugin) as writer:
        conn = writer.add_connection(topic, joint_state.__msgtype__, typestore=store)
        if robot_modes:
            mode_type = store.types["ur_dashboard_msgs/msg/RobotMode"]
            mode_conn = writer.add_connection(
                "/io_and_status_controller/robot_mode", mode_type.__msgtype__, typestore=store
            )
            for ns, mode in robot_modes:
                raw = store.serialize_cdr(mode_type(mode=mode), mode_type.__msgtype__)
                writer.write(mode_conn, ns, raw)
        for name in other_topics:
            float64 = store.types["std_msgs/msg/Float64"]
            other = writer.add_connection(name, float64.__msgtype__, typestore=store)
            writer.write(other, 1, store.serialize_cdr(float64(data=1.0), float64.__msgtype__))
        for k, tk in enumerate(times):
            received = round(float(tk) * 1e9)
            ns = received if stamps_ns is None else int(stamps_ns[k])
            order = (
                rng.permutation(len(all_names)) if rng is not None else np.arange(len(all_names))
            )
            values = [
                np.empty(0) if col is None else np.append(col[k], [0.01] if extra else [])[order]
                for col in columns
            ]
            msg = joint_state(
                header(stamp(ns // 1_000_000_000, ns % 1_000_000_000), "base"),
                [str(n) for n in all_names[order]],
                *values,
            )
            writer.write(conn, received, store.serialize_cdr(msg, joint_state.__msgtype__))
    return path
