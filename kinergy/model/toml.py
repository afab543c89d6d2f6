"""Robot files: TOML in and out, and the plain-dict form used for JSON.

One schema: a robot file is TOML with the same structure as :func:`robot_to_dict`, which is also
the ``robot show --json`` shape and what the URDF export embeds (its ``<kinergy:robot>`` element,
version :data:`ROBOT_SCHEMA`); :func:`robot_from_dict` reads it back from any of them::

    name = "ur5e"
    convention = "dh"                 # or "mdh"
    gravity = [0.0, 0.0, -9.81]       # optional
    standby_power = 0.0               # optional, W: the arm's electronics and brakes, drawn whatever the motion
    bus_voltage = 48.0                # optional, V: DC bus of the joints
    [uncertainty]                     # optional: identified parameters' errors (model/uncertainty.py)
    method = "jackknife over 10 time blocks"
    dof = 9
    parameters = ["joints[0].rotor_inertia", "joints[0].torque_constant", "standby_power"]
    modes = [[...], ...]              # K rows x p: the covariance is modes^T modes
    description = "..."               # optional
    coupling = [[...], ...]           # optional, n x n (differential joints)
    [flange]                          # optional: pose of the flange in the last link frame
    xyz = [0, 0, 0]
    rpy = [0, 0, 0]                   # rad, fixed-axis roll-pitch-yaw (URDF's convention)
    [base]                            # optional: pose of frame 0 in the base frame
    xyz = [0, 0, 0]
    rpy = [0, 0, 0]
    [payload]                         # optional
    mass = 1.0
    com = [0, 0, 0.05]
    inertia = [0, 0, 0, 0, 0, 0]
    [sources.inertia]                 # optional provenance per parameter group
    status = "seed"
    ref = "UR5e doc Table III"
    [[joints]]
    name = "shoulder_pan"
    d = 0.1625
    a = 0.0
    alpha = 1.5707963267948966
    offset = 0.0
    mass = 3.761
    com = [0.0, -0.02561, 0.00193]
    inertia = [0.0067, 0.0064, 0.0067, 0.0, 0.0, 0.0]   # Ixx Iyy Izz Ixy Iyz Ixz, about the CoM
    [joints.drive]
    gear_ratio = 100.0
    ...
    [joints.drive.friction]
    model = "power_flow"
    ...
    [joints.drive.thermal]            # optional: first-order thermal model (drives/thermal.py)
    capacity = 1000.0                 # J/K
    resistance = 1.2                  # K/W
    [joints.limits]
    position = [-6.283185307179586, 6.283185307179586]
    speed = 3.141592653589793
    torque = 150.0
    continuous = true                 # optional: no end stop (positions beyond the range are fine)
    [joints.torque_sensor]            # optional: what a logged joint torque of this joint measures
    side = "link"                     # "link" (default: between gear and link) or "motor"
    offset = 0.0                      # N m, what it reads at zero torque (identify --target torque)

Every error names the file and the field, e.g.
``ur5e.toml: joints[4] (wrist_2).inertia: ... violates the triangle inequality``.
"""

from __future__ import annotations

import os
from collections.abc import Callable, Collection, Mapping, Sequence
from typing import Any, TypeVar

import numpy as np
import tomli_w

from kinergy import checks
from kinergy.errors import KinergyError
from kinergy.files import atomic_write, read_toml
from kinergy.model.frames import matrix_rpy, rpy_matrix
from kinergy.model.robot import (
    SOURCE_CATEGORIES,
    Drive,
    Friction,
    Identified,
    InputRecord,
    Joint,
    Limits,
    Link,
    Payload,
    Robot,
    SensorSide,
    Source,
    Thermal,
    TorqueSensor,
)
from kinergy.model.uncertainty import uncertainty_from_dict, uncertainty_to_dict

__all__ = [
    "ROBOT_SCHEMA",
    "identified_to_dict",
    "parse_payload",
    "read_robot_toml",
    "robot_from_dict",
    "robot_to_dict",
    "save_robot",
]

T = TypeVar("T")

#: the version of the robot-file schema (the dictionary of :func:`robot_to_dict`), written where
#: the dictionary travels inside another format (the URDF export's ``<kinergy:robot version>``)
ROBOT_SCHEMA = 1

_ROBOT_KEYS = {
    "identified",
    "name",
    "convention",
    "gravity",
    "description",
    "coupling",
    "flange",
    "base",
    "payload",
    "sources",
    "joints",
    "standby_power",
    "bus_voltage",
    "uncertainty",
}
_JOINT_KEYS = {
    "name",
    "d",
    "a",
    "alpha",
    "offset",
    "mass",
    "com",
    "inertia",
    "drive",
    "limits",
    "torque_sensor",
}
_SENSOR_KEYS = ("side", "offset")
#: a drive's numbers every file gives, in the order files list them
_DRIVE_NUMBERS = (
    "gear_ratio",
    "motor_inertia",
    "reducer_inertia",
    "torque_constant",
    "motor_constant",
    "kt_over_kb",
)
_DRIVE_KEYS = {*_DRIVE_NUMBERS, "friction", "winding_resistance", "thermal"}
_THERMAL_KEYS = ("capacity", "resistance")
_LIMIT_KEYS = {"position", "speed", "torque", "acceleration", "continuous"}
#: friction parameters a file may not make negative: each is a friction (it opposes the motion)
#: or a rate (Makkar's gamma2, gamma3, gamma5; nursing eq 13); gamma1 may take either sign
_NON_NEGATIVE_FRICTION = {
    "viscous",
    "coulomb",
    "coulomb_direct",
    "coulomb_reverse",
    "static",
    "motor_viscous",
    "motor_coulomb",
    "reducer_coulomb",
    *(f"gamma{k}" for k in range(2, 7)),
}
#: the largest magnitude of a friction parameter in a file (N m, N m s/rad, s/rad: far above any
#: motor's, small enough that the torques stay finite)
_FRICTION_MAX = 1e6
#: the heaviest payload ``--payload`` takes, kg (the largest arms carry a few hundred)
_PAYLOAD_MAX = 1e4


def _at(where: str, build: Callable[[], T]) -> T:
    """Run ``build``; prefix any KinergyError (or missing key) with ``where``."""
    try:
        return build()
    except KinergyError as exc:
        raise exc.prefixed(where) from None


def _table(data: Any, where: str) -> Mapping[str, Any]:
    if not isinstance(data, Mapping):
        raise KinergyError(f"{where}: must be a table, got {type(data).__name__}")
    return data


def _take(data: Mapping[str, Any], key: str, where: str) -> Any:
    if key not in data:
        raise KinergyError(f"{where}: missing field {key!r}")
    return data[key]


def _known(data: Any, allowed: Collection[str], where: str) -> Mapping[str, Any]:
    """``data`` as a table whose keys are all ``allowed`` (errors name ``where``)."""
    data = _table(data, where)
    unknown = sorted(set(data) - set(allowed))
    if unknown:
        raise KinergyError(
            f"{where}: unknown field(s) {', '.join(repr(u) for u in unknown)} "
            f"(allowed: {', '.join(sorted(allowed))})"
        )
    return data


def _fields(
    data: Mapping[str, Any],
    where: str,
    required: Sequence[str],
    optional: Mapping[str, Any] | None = None,
) -> dict[str, Any]:
    """The ``required`` fields of a table (the first missing one is an error naming ``where``)
    and the ``optional`` ones, their default where absent: keyword arguments of a dataclass."""
    out = {key: _take(data, key, where) for key in required}
    out.update({key: data.get(key, default) for key, default in (optional or {}).items()})
    return out


def _check_friction_values(params: Mapping[str, Any], where: str) -> None:
    """Signs and sizes a friction model's numbers may have in a robot file (names the field)."""
    for name, value in params.items():
        sign = {"ge": 0.0} if name in _NON_NEGATIVE_FRICTION else {}  # friction opposes motion
        checks.number(value, f"{where}.{name}", size=_FRICTION_MAX, **sign)


def _joint_from_dict(data: Any, index: int) -> Joint:
    where = f"joints[{index}]"
    data = _table(data, where)
    if isinstance(data.get("name"), str):
        where = f"joints[{index}] ({data['name']})"
    data = _known(data, _JOINT_KEYS, where)

    link_fields = _fields(data, where, ("mass", "com", "inertia"))
    link = _at(where, lambda: Link(**link_fields))
    dwhere = f"{where}.drive"
    drive_data = _known(_take(data, "drive", where), _DRIVE_KEYS, dwhere)
    fwhere = f"{dwhere}.friction"
    fric_data = dict(_table(_take(drive_data, "friction", dwhere), fwhere))
    model = fric_data.pop("model", None)
    if model is None:
        raise KinergyError(f"{fwhere}: missing field 'model'")
    _check_friction_values(fric_data, fwhere)
    friction = _at(fwhere, lambda: Friction(model=model, params=fric_data))
    thermal = _thermal_from_dict(drive_data.get("thermal"), f"{dwhere}.thermal")
    drive_fields = _fields(drive_data, dwhere, _DRIVE_NUMBERS, {"winding_resistance": None})
    drive = _at(dwhere, lambda: Drive(**drive_fields, friction=friction, thermal=thermal))
    lwhere = f"{where}.limits"
    lim_data = _known(_take(data, "limits", where), _LIMIT_KEYS, lwhere)
    limit_fields = _fields(
        lim_data,
        lwhere,
        ("position", "speed", "torque"),
        {"acceleration": None, "continuous": False},
    )
    limits = _at(where, lambda: Limits(**limit_fields))
    joint_fields = _fields(data, where, ("name", "d", "a", "alpha"), {"offset": 0.0})
    sensor = _sensor_from_dict(data.get("torque_sensor"), where)
    return _at(
        where,
        lambda: Joint(**joint_fields, link=link, drive=drive, limits=limits, torque_sensor=sensor),
    )


def _sensor_from_dict(data: Any, where: str) -> TorqueSensor:
    """A joint's ``torque_sensor`` table (absent: a link-side sensor without offset)."""
    if data is None:
        return TorqueSensor()
    data = _known(data, _SENSOR_KEYS, f"{where}.torque_sensor")
    fields = _fields(data, where, (), {"side": SensorSide.LINK, "offset": 0.0})
    return _at(where, lambda: TorqueSensor(**fields))


def _thermal_from_dict(data: Any, where: str) -> Thermal | None:
    if data is None:
        return None
    data = _known(data, _THERMAL_KEYS, where)
    fields = _fields(data, where, _THERMAL_KEYS)
    return _at(where, lambda: Thermal(**fields))


def _pose_from_dict(data: Any, where: str) -> np.ndarray:
    data = _known(data, ("xyz", "rpy"), where)
    try:
        xyz = np.asarray(data.get("xyz", [0.0, 0.0, 0.0]), dtype=float)
        rpy = np.asarray(data.get("rpy", [0.0, 0.0, 0.0]), dtype=float)
    except (TypeError, ValueError):
        raise KinergyError(f"{where}: xyz and rpy must be 3 numbers each") from None
    if xyz.shape != (3,) or rpy.shape != (3,):
        raise KinergyError(f"{where}: xyz and rpy must be 3 numbers each")
    out = np.eye(4)
    out[:3, :3] = rpy_matrix(rpy)
    out[:3, 3] = xyz
    return out


def robot_from_dict(data: Mapping[str, Any]) -> Robot:
    """Build a :class:`Robot` from the plain-dict form (see the module docstring).

    Raises
    ------
    KinergyError
        Naming the field at fault (``joints[2] (elbow).drive.gear_ratio: ...``).
    """
    data = _known(data, _ROBOT_KEYS, "robot")
    joints_data = _take(data, "joints", "robot")
    if not isinstance(joints_data, list) or not joints_data:
        raise KinergyError("joints: must be a non-empty array of tables ([[joints]])")
    joints = [_joint_from_dict(j, i) for i, j in enumerate(joints_data)]
    payload = None
    if "payload" in data:
        pdata = _known(data["payload"], ("mass", "com", "inertia"), "payload")
        optional = {"com": [0.0, 0.0, 0.0], "inertia": [0.0] * 6}
        payload = Payload(**_fields(pdata, "payload", ("mass",), optional)).check_reach()
    sources = {}
    for cat, sdata in _table(data.get("sources", {}), "sources").items():
        sdata = _known(sdata, ("status", "ref"), f"sources.{cat}")
        status = _take(sdata, "status", f"sources.{cat}")
        try:
            sources[cat] = Source(status=status, ref=str(sdata.get("ref", "")))
        except KinergyError as exc:
            raise exc.prefixed(f"sources.{cat}") from None
    flange = _pose_from_dict(data["flange"], "flange") if "flange" in data else np.eye(4)
    base = _pose_from_dict(data["base"], "base") if "base" in data else np.eye(4)
    identified = _identified(data["identified"]) if "identified" in data else None
    uncertainty = uncertainty_from_dict(data["uncertainty"]) if "uncertainty" in data else None
    return Robot(
        name=_take(data, "name", "robot"),
        convention=_take(data, "convention", "robot"),
        joints=tuple(joints),
        gravity=data.get("gravity", [0.0, 0.0, -9.81]),
        payload=payload,
        flange=flange,
        base=base,
        coupling=data.get("coupling"),
        sources=sources,
        description=str(data.get("description", "")),
        standby_power=data.get("standby_power", 0.0),
        bus_voltage=data.get("bus_voltage", 48.0),
        identified=identified,
        uncertainty=uncertainty,
    )


def _identified(data: Any) -> Identified:
    """The ``[identified]`` table: where a model was identified from."""
    where = "identified"
    data = _known(data, ("kinergy", "command", "options", "inputs", "accepted"), where)
    options = _table(data.get("options", {}), f"{where}.options")
    for key, value in options.items():
        if not isinstance(value, str | float | int | bool):
            raise KinergyError(f"{where}.options.{key}: must be a string, number or boolean")
    inputs = []
    raw = data.get("inputs", [])
    if not isinstance(raw, list):
        raise KinergyError(f"{where}.inputs: must be an array of tables ([[identified.inputs]])")
    for k, item in enumerate(raw):
        at = f"{where}.inputs[{k}]"
        item = _known(item, ("path", "sha256", "size", "rows"), at)
        try:
            inputs.append(
                InputRecord(
                    path=str(_take(item, "path", at)),
                    sha256=str(_take(item, "sha256", at)),
                    size=int(_take(item, "size", at)),
                    rows=int(_take(item, "rows", at)),
                )
            )
        except (TypeError, ValueError):
            raise KinergyError(f"{at}: size and rows must be integers") from None
    accepted = data.get("accepted", [])
    if not isinstance(accepted, list) or not all(isinstance(a, str) for a in accepted):
        raise KinergyError(f"{where}.accepted: must be an array of strings")
    return Identified(
        kinergy=str(data.get("kinergy", "")),
        command=str(data.get("command", "")),
        options=dict(options),
        inputs=tuple(inputs),
        accepted=tuple(accepted),
    )


def identified_to_dict(ident: Identified) -> dict[str, Any]:
    """The ``[identified]`` table of a robot file (:class:`~kinergy.model.robot.Identified`)."""
    return {
        "kinergy": ident.kinergy,
        "command": ident.command,
        "options": dict(ident.options),
        "accepted": list(ident.accepted),
        "inputs": [
            {"path": i.path, "sha256": i.sha256, "size": i.size, "rows": i.rows}
            for i in ident.inputs
        ],
    }


def _floats(arr: Any) -> Any:
    return np.asarray(arr, dtype=float).tolist()


def robot_to_dict(robot: Robot) -> dict[str, Any]:
    """The plain-dict form of a robot: TOML file content and the ``robot show --json`` shape.

    Optional items that are absent (no payload, identity flange, no coupling, no winding
    resistance, no thermal model, no acceleration limit) are left out.
    """
    out: dict[str, Any] = {
        "name": robot.name,
        "description": robot.description,
        "convention": robot.convention,
        "gravity": _floats(robot.gravity),
        "standby_power": robot.standby_power,
        "bus_voltage": robot.bus_voltage,
    }
    assert robot.coupling is not None
    if not np.array_equal(robot.coupling, np.eye(robot.n)):
        out["coupling"] = _floats(robot.coupling)
    for key, pose in (("base", robot.base), ("flange", robot.flange)):
        if not np.array_equal(pose, np.eye(4)):
            rpy = matrix_rpy(pose[:3, :3])
            out[key] = {"xyz": _floats(pose[:3, 3]), "rpy": _floats(rpy)}
    if robot.payload is not None:
        out["payload"] = {
            "mass": robot.payload.mass,
            "com": _floats(robot.payload.com),
            "inertia": _floats(robot.payload.inertia),
        }
    out["sources"] = {
        cat: {"status": robot.sources[cat].status, "ref": robot.sources[cat].ref}
        for cat in SOURCE_CATEGORIES
    }
    if robot.identified is not None:
        out["identified"] = identified_to_dict(robot.identified)
    if robot.uncertainty is not None:
        out["uncertainty"] = uncertainty_to_dict(robot.uncertainty)
    joints = []
    for j in robot.joints:
        drive: dict[str, Any] = {key: getattr(j.drive, key) for key in _DRIVE_NUMBERS}
        if j.drive.winding_resistance is not None:
            drive["winding_resistance"] = j.drive.winding_resistance
        drive["friction"] = j.drive.friction.as_dict()
        if j.drive.thermal is not None:
            drive["thermal"] = {key: getattr(j.drive.thermal, key) for key in _THERMAL_KEYS}
        limits: dict[str, Any] = {
            "position": _floats(j.limits.position),
            "speed": j.limits.speed,
            "torque": j.limits.torque,
        }
        if j.limits.acceleration is not None:
            limits["acceleration"] = j.limits.acceleration
        if j.limits.continuous:
            limits["continuous"] = True
        joint: dict[str, Any] = {
            "name": j.name,
            "d": j.d,
            "a": j.a,
            "alpha": j.alpha,
            "offset": j.offset,
            "mass": j.link.mass,
            "com": _floats(j.link.com),
            "inertia": _floats(j.link.inertia),
            "drive": drive,
            "limits": limits,
        }
        if j.torque_sensor != TorqueSensor():
            sensor = j.torque_sensor
            joint["torque_sensor"] = {"side": sensor.side.value, "offset": sensor.offset}
        joints.append(joint)
    out["joints"] = joints
    return out


def read_robot_toml(path: str | os.PathLike[str]) -> Robot:
    """Read a TOML robot file.

    Raises
    ------
    KinergyError
        ``FILE: problem`` for unreadable files, TOML syntax errors (with line and column) and any
        invalid field.
    """
    data = read_toml(path, "robot file")
    try:
        return robot_from_dict(data)
    except KinergyError as exc:
        raise exc.prefixed(str(path)) from None


def save_robot(robot: Robot, path: str | os.PathLike[str], *, header: str = "") -> None:
    """Write ``robot`` as a TOML robot file, atomically (no half-written file on failure).

    ``header`` lines are written as TOML comments at the top.
    """
    body = tomli_w.dumps(robot_to_dict(robot))
    comment = "".join(f"# {line}\n" for line in header.splitlines())
    atomic_write(path, lambda fh: fh.write(comment + body))


def parse_payload(text: str) -> Payload:
    """Parse a CLI payload: ``MASS``, ``MASS,CX,CY,CZ`` or ``MASS,CX,CY,CZ,IXX,IYY,IZZ,IXY,IYZ,IXZ``.

    kg, m (flange frame), kg m^2 (about the centre of mass).
    """
    try:
        values = [float(v) for v in text.replace(" ", "").split(",") if v != ""]
    except ValueError:
        raise KinergyError(f"--payload: expected comma-separated numbers, got {text!r}") from None
    if len(values) not in (1, 4, 10):
        raise KinergyError(
            f"--payload: expected MASS, MASS,CX,CY,CZ or 10 numbers with the inertia; got {len(values)}"
        )
    if not 0.0 <= values[0] <= _PAYLOAD_MAX:
        raise KinergyError(
            f"--payload: mass must be from 0 to {_PAYLOAD_MAX:g} kg, got {values[0]:g}"
        )
    com = values[1:4] if len(values) >= 4 else [0.0, 0.0, 0.0]
    inertia = values[4:10] if len(values) == 10 else [0.0] * 6
    return _at(
        "--payload",
        lambda: Payload(
            mass=values[0], com=np.asarray(com), inertia=np.asarray(inertia)
        ).check_reach(),
    )
