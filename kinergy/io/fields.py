"""The names a log's columns may have: UR's RTDE output fields, and kinergy's own few.

A record.py log names its columns in a header line, a headerless one through ``--columns``; both
use the names of UR's Real-Time Data Exchange (RTDE) interface, an n-vector as ``name_0 ..
name_{n-1}``. :data:`FIELDS` says of each RTDE output field how wide it is: ``"joints"`` (one
value per joint: its width must be the robot's joint count), a fixed width (a TCP pose is 6
values, an accelerometer 3) or 1 (a scalar, integers and bit masks included). The list is UR's
RTDE guide's output table for e-Series controllers (PolyScope 5, as UR's client library
``ur_client_library``, ``src/rtde/data_package.cpp``, types it), registers included:
``output_bit_registers0_to_31`` and ``output_bit_registers32_to_63`` (32 bits in one number),
``output_bit_register_64`` .. ``_127``, ``output_int_register_0`` .. ``_47``,
``output_double_register_0`` .. ``_47`` and the ``input_`` ones an output recipe may read back.
:func:`closest` finds the known name a misspelt one was meant to be.

Besides RTDE's fields kinergy reads ``actual_joint_torque`` (measured joint torques, N m, of arms
with joint torque sensors), ``actual_qdd`` (measured joint accelerations, rad/s², where a logger
has them: used instead of differentiating the speed) and ``segment`` (the recorder's
reconnection count, :mod:`kinergy.live.recorder`). A column spec entry ``_`` (or ``_:n``) skips
columns kinergy should not read.

RTDE's state codes (UR's RTDE guide): ``robot_mode`` 7 is RUNNING (powered, brakes released);
``safety_mode`` 1 NORMAL and 2 REDUCED let the arm move, the others stop it;
``runtime_state`` 0 stopping, 1 stopped, 2 playing, 3 pausing, 4 paused, 5 resuming.

Examples
--------
>>> width("actual_q", 6), width("actual_TCP_pose", 6), width("runtime_state", 6)
(6, 6, 1)
>>> is_known("output_int_register_12"), is_known("output_bit_registers0_to_31")
(True, True)
>>> closest("actual_curent")
'actual_current'
"""

from __future__ import annotations

import difflib
import re
from collections.abc import Mapping

import numpy as np

from kinergy.errors import KinergyError

__all__ = [
    "CHECKED_SIGNALS",
    "FIELDS",
    "JOINTS",
    "KINERGY_FIELDS",
    "ROBOT_RUNNING",
    "SAFETY_MOVING",
    "SKIP",
    "USED",
    "check_widths",
    "closest",
    "is_known",
    "vector_member",
    "width",
]

#: the width of a field that holds one value per joint
JOINTS = "joints"
#: the column spec entry that skips a column (``_:n`` skips n)
SKIP = "_"

#: ``robot_mode`` RUNNING: the arm is powered, its brakes released, under control
ROBOT_RUNNING = 7
#: ``safety_mode`` NORMAL and REDUCED: the safety system lets the arm move
SAFETY_MOVING = (1, 2)

#: RTDE's output fields (UR's RTDE guide, e-Series, PolyScope 5), registers aside: name -> width
RTDE_FIELDS: dict[str, int | str] = {
    "timestamp": 1,
    # joint space, one value per joint
    "target_q": JOINTS,
    "target_qd": JOINTS,
    "target_qdd": JOINTS,
    "target_current": JOINTS,
    "target_moment": JOINTS,
    "actual_q": JOINTS,
    "actual_qd": JOINTS,
    "actual_current": JOINTS,
    "actual_current_window": JOINTS,
    "actual_current_as_torque": JOINTS,
    "joint_control_output": JOINTS,
    "joint_temperatures": JOINTS,
    "joint_mode": JOINTS,
    "actual_joint_voltage": JOINTS,
    # tool centre point, forces and the payload
    "actual_TCP_pose": 6,
    "actual_TCP_speed": 6,
    "actual_TCP_force": 6,
    "actual_TCP_acceleration": 6,
    "target_TCP_pose": 6,
    "target_TCP_speed": 6,
    "target_TCP_acceleration": 6,
    "tcp_offset": 6,
    "ft_raw_wrench": 6,
    "wrench_calc_from_currents": 6,
    "target_base_acceleration": 6,
    "target_base_wrench": 6,
    "payload_inertia": 6,
    "actual_tool_accelerometer": 3,
    "payload_cog": 3,
    "elbow_position": 3,
    "elbow_velocity": 3,
    "target_gravity": 3,
    "payload": 1,
    "tcp_force_scalar": 1,
    # robot, safety and program state
    "robot_mode": 1,
    "safety_mode": 1,
    "safety_status": 1,
    "runtime_state": 1,
    "robot_status_bits": 1,
    "safety_status_bits": 1,
    "actual_execution_time": 1,
    "target_execution_time": 1,
    "control_step": 1,
    "speed_scaling": 1,
    "target_speed_fraction": 1,
    "actual_momentum": 1,
    "script_control_line": 1,
    "joint_position_deviation_ratio": 1,
    "collision_detection_ratio": 1,
    "time_scale_source": 1,
    # power
    "actual_main_voltage": 1,
    "actual_robot_voltage": 1,
    "actual_robot_current": 1,
    "actual_robot_energy_consumed": 1,
    "actual_robot_braking_energy_dissipated": 1,
    # I/O
    "actual_digital_input_bits": 1,
    "actual_digital_output_bits": 1,
    "actual_configurable_digital_input_bits": 1,
    "actual_configurable_digital_output_bits": 1,
    "analog_io_types": 1,
    "standard_analog_input0": 1,
    "standard_analog_input1": 1,
    "standard_analog_output0": 1,
    "standard_analog_output1": 1,
    "io_current": 1,
    "encoder0_raw": 1,
    "encoder1_raw": 1,
    "euromap67_input_bits": 1,
    "euromap67_output_bits": 1,
    "euromap67_24V_voltage": 1,
    "euromap67_24V_current": 1,
    "tool_mode": 1,
    "tool_analog_input_types": 1,
    "tool_analog_input0": 1,
    "tool_analog_input1": 1,
    "tool_output_voltage": 1,
    "tool_output_current": 1,
    "tool_temperature": 1,
    "tool_output_mode": 1,
    "tool_digital_output0_mode": 1,
    "tool_digital_output1_mode": 1,
    "tool_digital_output_mask": 1,
    "tool_digital_output": 1,
    # the general-purpose bit registers as 32-bit masks (the numbered ones: :data:`REGISTERS`)
    "output_bit_registers0_to_31": 1,
    "output_bit_registers32_to_63": 1,
    "input_bit_registers0_to_31": 1,
    "input_bit_registers32_to_63": 1,
}

#: kinergy's own fields: name -> width
KINERGY_FIELDS: dict[str, int | str] = {
    "actual_joint_torque": JOINTS,
    "actual_qdd": JOINTS,
    "segment": 1,
}

#: every named field: RTDE's and kinergy's, name -> width
FIELDS: dict[str, int | str] = {**RTDE_FIELDS, **KINERGY_FIELDS}

#: the measured signals kinergy uses, which the log checks read whenever a log has them
CHECKED_SIGNALS = (
    *(f"{kind}_{x}" for kind in ("target", "actual") for x in ("q", "qd", "qdd")),
    "target_moment",
    "actual_current",
    "target_current",
    "actual_joint_torque",
    "actual_current_as_torque",
    "actual_joint_voltage",
    "joint_temperatures",
    "actual_robot_voltage",
    "actual_robot_current",
    "payload",
    "payload_cog",
    "payload_inertia",
)

#: the fields kinergy uses (the others are read only to be passed on): a value in them that is
#: not a number is a damaged line, where a logger's text in an unused field is ignored
USED = frozenset(
    {"timestamp", *CHECKED_SIGNALS, "robot_mode", "safety_mode", "runtime_state", "segment"}
)

#: RTDE's numbered registers (scalars): kind -> the numbers there are
REGISTERS = {"bit": range(64, 128), "int": range(48), "double": range(48)}
_REGISTER = re.compile(r"^(?:input|output)_(bit|int|double)_register_(\d+)$")
_VECTOR = re.compile(r"^(?P<name>.+)_(?P<index>\d+)$")


def is_known(name: str) -> bool:
    """Whether ``name`` is an RTDE field or one of kinergy's (a numbered register too)."""
    if name in FIELDS:
        return True
    m = _REGISTER.match(name)
    return m is not None and int(m[2]) in REGISTERS[m[1]]


def width(name: str, n_joints: int) -> int:
    """How many columns the known field ``name`` has on a robot of ``n_joints`` joints."""
    w = FIELDS.get(name, 1)
    return n_joints if w == JOINTS else int(w)


def vector_member(column: str) -> tuple[str, int] | None:
    """The vector field and index a column ``name_k`` belongs to (``actual_q_3`` -> ``("actual_q",
    3)``), or None when the column is no member of a known vector field (a scalar, a register, an
    unknown name). A fixed-width field's index must be below its width; a joint field's any."""
    if is_known(column):
        return None
    m = _VECTOR.match(column)
    if m is None or m["name"] not in FIELDS:
        return None
    w, k = FIELDS[m["name"]], int(m["index"])
    if w == 1 or (w != JOINTS and k >= int(w)):
        return None
    return m["name"], k


def closest(name: str, among: list[str] | None = None) -> str | None:
    """The name of ``among`` (default every known field) that ``name`` was most likely meant to
    be, or None when none is close (difflib's ratio at least 0.75, case ignored)."""
    pool = list(FIELDS) if among is None else among
    lowered = {p.lower(): p for p in pool}
    match = difflib.get_close_matches(name.lower(), list(lowered), n=1, cutoff=0.75)
    return lowered[match[0]] if match else None


def check_widths(signals: Mapping[str, np.ndarray], n: int, where: str) -> None:
    """Raise when a field of one value per joint (:data:`JOINTS`) in ``signals`` does not have
    ``n`` columns (``where: target_q has 7 joints but the robot has 6``)."""
    for name, x in signals.items():
        if FIELDS.get(name) == JOINTS and (x.ndim != 2 or x.shape[1] != n):
            width = 1 if x.ndim == 1 else x.shape[1]
            raise KinergyError(f"{where}: {name} has {width} joints but the robot has {n}")
