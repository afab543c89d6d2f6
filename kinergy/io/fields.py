"""The names a log's columns may have: UR's RTDE output fields, and kinergy's own few.

A record.py log names its columns in a header line, a headerless one through ``--columns``; both
use the names of UR's Real-Time Data Exchange (RTDE) interface, an n-vector as ``name_0 ..
name_{n-1}``. :data:`FIELDS` says of each name how wide it is: ``"joints"`` (one value per joint:
its width must be the robot's joint count), a fixed width (a TCP pose is 6 values, an
accelerometer 3) or 1 (a scalar). :func:`closest` finds the known name a misspelt one was meant
to be.

Besides RTDE's fields kinergy reads ``actual_joint_torque`` (measured joint torques, N m, of arms
with joint torque sensors) and ``segment`` (the recorder's reconnection count,
:mod:`kinergy.live.recorder`). A column spec entry ``_`` (or ``_:n``) skips columns kinergy
should not read.

Examples
--------
>>> width("actual_q", 6), width("actual_TCP_pose", 6), width("runtime_state", 6)
(6, 6, 1)
>>> closest("actual_curent")
'actual_current'
"""

from __future__ import annotations

import difflib
import re

__all__ = ["FIELDS", "JOINTS", "SKIP", "closest", "is_known", "width"]

#: the width of a field that holds one value per joint
JOINTS = "joints"
#: the column spec entry that skips a column (``_:n`` skips n)
SKIP = "_"

#: RTDE output fields (UR's RTDE guide, e-Series, PolyScope 5) and kinergy's own: name -> width
FIELDS: dict[str, int | str] = {
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
    "joint_position_deviation_ratio": JOINTS,
    # tool centre point and payload
    "actual_TCP_pose": 6,
    "actual_TCP_speed": 6,
    "actual_TCP_force": 6,
    "target_TCP_pose": 6,
    "target_TCP_speed": 6,
    "ft_raw_wrench": 6,
    "payload_inertia": 6,
    "actual_tool_accelerometer": 3,
    "payload_cog": 3,
    "elbow_position": 3,
    "elbow_velocity": 3,
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
    "speed_scaling": 1,
    "target_speed_fraction": 1,
    "speed_scaling_combined": 1,
    "actual_momentum": 1,
    "script_control_line": 1,
    "collision_detection_ratio": 1,
    "time_scale_source": 1,
    # power
    "actual_main_voltage": 1,
    "actual_robot_voltage": 1,
    "actual_robot_current": 1,
    # I/O
    "actual_digital_input_bits": 1,
    "actual_digital_output_bits": 1,
    "analog_io_types": 1,
    "standard_analog_input0": 1,
    "standard_analog_input1": 1,
    "standard_analog_output0": 1,
    "standard_analog_output1": 1,
    "io_current": 1,
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
    "output_bit_registers0_to_31": 1,
    "output_bit_registers32_to_63": 1,
    "input_bit_registers0_to_31": 1,
    "input_bit_registers32_to_63": 1,
    # kinergy's own
    "actual_joint_torque": JOINTS,
    "segment": 1,
}

#: RTDE's numbered registers, ``output_int_register_12``, ``input_double_register_3`` ...
_REGISTER = re.compile(r"^(input|output)_(bit|int|double)_register_\d+$")


def is_known(name: str) -> bool:
    """Whether ``name`` is an RTDE field or one of kinergy's (a register of any number too)."""
    return name in FIELDS or bool(_REGISTER.match(name))


def width(name: str, n_joints: int) -> int:
    """How many columns the known field ``name`` has on a robot of ``n_joints`` joints."""
    w = FIELDS.get(name, 1)
    return n_joints if w == JOINTS else int(w)


def closest(name: str, among: list[str] | None = None) -> str | None:
    """The name of ``among`` (default every known field) that ``name`` was most likely meant to
    be, or None when none is close (difflib's ratio at least 0.75, case ignored)."""
    pool = list(FIELDS) if among is None else among
    lowered = {p.lower(): p for p in pool}
    match = difflib.get_close_matches(name.lower(), list(lowered), n=1, cutoff=0.75)
    return lowered[match[0]] if match else None
