"""The robot model: plain, frozen data, validated on construction.

A :class:`Robot` is a serial chain of revolute :class:`Joint` s. Each joint carries its kinematic
parameters (standard or modified Denavit–Hartenberg, see :data:`CONVENTIONS`), the :class:`Link`
it moves (mass, centre of mass, inertia about the centre of mass in the link frame), its
:class:`Drive` (gear, motor, friction; motor side) and its :class:`Limits`. An optional
:class:`Payload` sits at the flange. Nothing here computes dynamics: algorithms are functions in
:mod:`kinergy.dynamics` that take a robot.

Units are SI throughout (m, rad, kg, kg m^2, N m, A). Inertia 6-vectors are
``[Ixx, Iyy, Izz, Ixy, Iyz, Ixz]`` about the centre of mass, in the link frame.
"""

from __future__ import annotations

import dataclasses
import enum
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from kinergy import checks
from kinergy.arrays import Array
from kinergy.errors import KinergyError
from kinergy.friction.model import FrictionModel
from kinergy.friction.registry import get_model
from kinergy.model.uncertainty import Uncertainty, parameter_value

__all__ = [
    "CONVENTIONS",
    "MAGNITUDES",
    "SOURCE_CATEGORIES",
    "SOURCE_STATUSES",
    "Convention",
    "Drive",
    "Friction",
    "Identified",
    "InputRecord",
    "Joint",
    "Limits",
    "Link",
    "Payload",
    "Robot",
    "SensorSide",
    "Source",
    "Thermal",
    "TorqueSensor",
    "inertia_matrix",
    "transmission_matrix",
]


class Convention(enum.StrEnum):
    """How a robot's joints give its link frames.

    ``DH``: frame i = frame i-1 · Rz(q_i + offset_i) · Tz(d_i) · Tx(a_i) · Rx(alpha_i).
    ``MDH`` (Craig): frame i = frame i-1 · Rx(alpha_{i-1}) · Tx(a_{i-1}) · Rz(q_i + offset_i) ·
    Tz(d_i), with joint i storing ``a`` = a_{i-1} and ``alpha`` = alpha_{i-1}.
    """

    DH = "dh"
    MDH = "mdh"


#: the conventions' names, as files write them
CONVENTIONS = tuple(c.value for c in Convention)

#: Groups of parameters whose provenance a robot file records.
SOURCE_CATEGORIES = (
    "kinematics",
    "mass",
    "com",
    "inertia",
    "drive_inertia",
    "torque_constant",
    "friction",
    "motor_constant",
    "limits",
    "thermal",
    "supply",
)
#: ``published`` by the maker, from a ``seed`` paper's tables, ``identified`` from logs by kinergy,
#: ``calibration`` (fitted to the maker's joint calibration, ``robot import-calibration``),
#: ``nominal`` (an estimate: identify before trusting), or ``user`` (a file that does not say).
SOURCE_STATUSES = ("published", "seed", "identified", "calibration", "nominal", "user")


#: the largest magnitude each parameter may have (SI units): far beyond any real arm, small enough
#: that the dynamics stay finite; a file with ``gravity = [0, 0, 1e308]`` is refused, not run
MAGNITUDES = {
    # links: loose, since a full identification may give a link that the logs cannot see
    # (its base parameters unidentifiable) a mass of 1e8 kg; still far from overflow
    "mass": 1e12,  # kg
    "com": 1e6,  # m
    "inertia": 1e15,  # kg m^2
    "d": 100.0,  # m
    "a": 100.0,
    "alpha": 100.0,  # rad
    "offset": 100.0,
    "gear_ratio": 1e6,
    "motor_inertia": 1e3,  # kg m^2
    "reducer_inertia": 1e3,
    "torque_constant": 1e3,  # N m/A
    "motor_constant": 1e3,  # N m/sqrt(W)
    "kt_over_kb": 100.0,
    "winding_resistance": 1e6,  # ohm
    "limits.position": 1e3,  # rad
    "limits.speed": 1e3,  # rad/s
    "limits.torque": 1e7,  # N m
    "limits.acceleration": 1e6,  # rad/s^2
    "gravity": 100.0,  # m/s^2, about 10 g
    "standby_power": 1e6,  # W
    "bus_voltage": 1e4,  # V
    "torque_sensor.offset": 1e4,  # N m
}


def _vector(value: Any, length: int, what: str) -> Array:
    """``length`` finite numbers no larger than :data:`MAGNITUDES` allows for ``what``."""
    return checks.vector(value, what, length=length, size=MAGNITUDES.get(what))


def _number(value: Any, what: str, *, low: float | None = None, strict: bool = True) -> float:
    """A finite number above ``low`` (or at least it, not ``strict``), within
    :data:`MAGNITUDES`."""
    gt, ge = (low, None) if strict else (None, low)
    return checks.number(value, what, gt=gt, ge=ge, size=MAGNITUDES.get(what))


def inertia_matrix(inertia: Array) -> Array:
    """Symmetric 3x3 tensor from ``[Ixx, Iyy, Izz, Ixy, Iyz, Ixz]``, shape (..., 6) -> (..., 3, 3)."""
    ixx, iyy, izz, ixy, iyz, ixz = np.moveaxis(np.asarray(inertia, dtype=float), -1, 0)
    return np.stack(
        [
            np.stack([ixx, ixy, ixz], axis=-1),
            np.stack([ixy, iyy, iyz], axis=-1),
            np.stack([ixz, iyz, izz], axis=-1),
        ],
        axis=-2,
    )


def _check_inertia(inertia: Array, what: str, *, allow_zero: bool) -> None:
    """Positive (semi-)definite and satisfying the triangle inequality of principal moments."""
    eig = np.linalg.eigvalsh(inertia_matrix(inertia))
    scale = max(float(np.max(np.abs(eig))), 1e-12)
    if allow_zero and scale <= 1e-12:
        return
    if eig[0] <= (-1e-12 * scale if allow_zero else 0.0):
        raise KinergyError(
            f"{what} is not positive definite (principal moments {np.round(eig, 9).tolist()})"
        )
    if eig[0] + eig[1] < eig[2] * (1.0 - 1e-9):
        raise KinergyError(
            f"{what} violates the triangle inequality: principal moments "
            f"{np.round(eig, 9).tolist()} (the two smaller must add up to at least the largest)"
        )


@dataclass(frozen=True, eq=False)
class Link:
    """Rigid-body data of one link, in its own frame (DH or MDH frame i).

    Attributes
    ----------
    mass : float
        kg, > 0.
    com : ndarray, shape (3,)
        Centre of mass, m, in the link frame.
    inertia : ndarray, shape (6,)
        ``[Ixx, Iyy, Izz, Ixy, Iyz, Ixz]`` about the centre of mass, kg m^2, in the link frame;
        positive definite and satisfying the triangle inequality.
    """

    mass: float
    com: Array
    inertia: Array

    def __post_init__(self) -> None:
        object.__setattr__(self, "mass", _number(self.mass, "mass", low=0.0))
        object.__setattr__(self, "com", _vector(self.com, 3, "com"))
        object.__setattr__(self, "inertia", _vector(self.inertia, 6, "inertia"))
        _check_inertia(self.inertia, "inertia", allow_zero=False)


#: m: farthest a payload's centre of mass may be from the flange (a tool held by an arm; a
#: larger figure is a unit slip, mm for m)
PAYLOAD_REACH = 1.0


@dataclass(frozen=True, eq=False)
class Payload:
    """A load rigidly fixed to the flange (what a UR program sets with ``set_payload``).

    Attributes
    ----------
    mass : float
        kg, >= 0.
    com : ndarray, shape (3,)
        Centre of mass in the flange frame, m.
    inertia : ndarray, shape (6,)
        About the centre of mass, flange-frame axes, kg m^2; zeros for a point mass.
    """

    mass: float
    com: Array = field(default_factory=lambda: np.zeros(3))
    inertia: Array = field(default_factory=lambda: np.zeros(6))

    def __post_init__(self) -> None:
        object.__setattr__(self, "mass", _number(self.mass, "payload mass", low=0.0, strict=False))
        object.__setattr__(self, "com", _vector(self.com, 3, "payload com"))
        object.__setattr__(self, "inertia", _vector(self.inertia, 6, "payload inertia"))
        _check_inertia(self.inertia, "payload inertia", allow_zero=True)

    def check_reach(self) -> Payload:
        """This payload, refused when its centre of mass is farther than :data:`PAYLOAD_REACH`
        from the flange (a unit slip in what a user wrote: mm for m)."""
        reach = float(np.linalg.norm(self.com))
        if reach > PAYLOAD_REACH:
            raise KinergyError(
                f"payload com is {reach:g} m from the flange, beyond {PAYLOAD_REACH:g} m: given in "
                "mm instead of m?"
            )
        return self


@dataclass(frozen=True, eq=False)
class Friction:
    """A joint's friction: its model (family) and motor-side parameters.

    Attributes
    ----------
    model : FrictionModel
        The family (:mod:`kinergy.friction`); given by name (``"power_flow"``), it is resolved
        here, once.
    params : mapping of str to float
        Its parameters, motor side (checked against the family's).
    """

    model: FrictionModel
    params: Mapping[str, float]

    def __post_init__(self) -> None:
        model = get_model(self.model)
        object.__setattr__(self, "model", model)
        object.__setattr__(self, "params", model.check(dict(self.params)))

    @property
    def name(self) -> str:
        """The family's name, as robot files write it."""
        return self.model.name

    def torque(
        self,
        wm: Array,
        tau_load: Array | None = None,
        dwm: Array | None = None,
        *,
        temperature: Array | None = None,
    ) -> Array:
        """Friction torque, motor side, N m, like ``wm`` (rad/s; see
        :meth:`~kinergy.friction.model.FrictionModel.friction_torque`)."""
        return self.model.friction_torque(self.params, wm, tau_load, dwm, temperature=temperature)

    @property
    def values(self) -> Array:
        """The values of the family's linear parameters, shape (k,)."""
        return self.model.values_of(self.params)

    def with_values(self, values: Array) -> Friction:
        """This friction with its linear parameters replaced by ``values`` (k,)."""
        return Friction(self.model, self.model.with_values(self.params, values))

    def as_dict(self) -> dict[str, str | float]:
        """``{"model": name, **parameters}``: a robot file's ``[joints.drive.friction]`` table."""
        return {"model": self.model.name, **self.params}


@dataclass(frozen=True, eq=False)
class Thermal:
    """A joint's first-order thermal model (:mod:`kinergy.drives.thermal`): one heat capacity
    warmed by the drive's losses and cooled to ambient through one thermal resistance.

    Attributes
    ----------
    capacity : float
        C, J/K, > 0: the heat that warms the joint by one kelvin.
    resistance : float
        R_th, K/W, > 0: the joint's steady temperature rise per watt of loss.
    """

    capacity: float
    resistance: float

    def __post_init__(self) -> None:
        for name in ("capacity", "resistance"):
            object.__setattr__(self, name, _number(getattr(self, name), name, low=0.0))


@dataclass(frozen=True, eq=False)
class Drive:
    """A joint drive: motor, reducer and their friction, described on the motor side.

    Attributes
    ----------
    gear_ratio : float
        Motor speed / joint speed (UR5e eq 2's ``i``), non-zero; its sign sets the direction.
    motor_inertia, reducer_inertia : float
        J_m and J_r, kg m^2, motor side, >= 0 (UR5e Table IV).
    torque_constant : float
        k_t, N m/A, > 0 (UR5e eq 10).
    motor_constant : float
        k_m = k_t / sqrt(R), N m/sqrt(W), > 0 (UR5e eq 23).
    kt_over_kb : float
        Ratio of torque constant to back-EMF constant, > 0 (0.89 for the UR5e motors).
    friction : Friction
        Motor-side friction model.
    winding_resistance : float or None
        R, ohm, > 0, when known; overrides ``motor_constant`` in the electrical model.
    thermal : Thermal or None
        The joint's thermal model, when known (the twin warms its joints with it).
    """

    gear_ratio: float
    motor_inertia: float
    reducer_inertia: float
    torque_constant: float
    motor_constant: float
    kt_over_kb: float
    friction: Friction
    winding_resistance: float | None = None
    thermal: Thermal | None = None

    def __post_init__(self) -> None:
        ratio = _number(self.gear_ratio, "gear_ratio")
        if ratio == 0.0:
            raise KinergyError("gear_ratio must be non-zero")
        object.__setattr__(self, "gear_ratio", ratio)
        for name in ("motor_inertia", "reducer_inertia"):
            object.__setattr__(
                self, name, _number(getattr(self, name), name, low=0.0, strict=False)
            )
        for name in ("torque_constant", "motor_constant", "kt_over_kb"):
            object.__setattr__(self, name, _number(getattr(self, name), name, low=0.0))
        if self.winding_resistance is not None:
            object.__setattr__(
                self,
                "winding_resistance",
                _number(self.winding_resistance, "winding_resistance", low=0.0),
            )
        if not isinstance(self.friction, Friction):
            raise KinergyError("friction must be a Friction")
        if self.thermal is not None and not isinstance(self.thermal, Thermal):
            raise KinergyError("thermal must be a Thermal")

    @property
    def rotor_inertia(self) -> float:
        """J_m + J_r, kg m^2, motor side (UR5e eq 9)."""
        return self.motor_inertia + self.reducer_inertia


class SensorSide(enum.StrEnum):
    """Where a joint's torque sensor sits in its drive train (:class:`TorqueSensor`).

    ``LINK``: between the gear's output and the link (the Panda, KUKA's LBR, Kinova's Gen3 and
    most torque-controlled arms); ``MOTOR``: before the gear, so that it carries the rotor's and
    the gear's inertia and friction too (or a joint torque the controller reckons from the motor
    current).
    """

    LINK = "link"
    MOTOR = "motor"


@dataclass(frozen=True)
class TorqueSensor:
    """A joint's torque sensor: where it sits and what it reads at zero torque.

    What it measures, joint side (N m), with ``tau_rb`` the links' rigid-body torques (RNEA),
    ``N`` the transmission (``wm = N qd``), ``J = J_m + J_r`` the rotor inertias and ``F(wm)``
    the drives' friction (motor side), as :func:`kinergy.predict.sensor_torque` computes it::

        link side:   tau_s = tau_rb(q, qd, qdd) + N^T F(wm)                      + offset
        motor side:  tau_s = tau_rb(q, qd, qdd) + N^T F(wm) + N^T diag(J) N qdd  + offset

    A link-side sensor carries the link, and whatever rubs between the sensor and the link, but
    not the rotor: the rotor's inertia torque ``J wm_dot`` is spent before the gear, on the
    motor side of the sensor, so the sensor cannot see it (UR5e eq 2's second term is missing
    from its reading). Of the drive's friction it sees only the part between the sensor and the
    link (output bearings, seals); kinergy's joint holds one friction, so a model identified
    from link-side sensors holds that part (the motor's and the gear's are invisible to the
    sensor, and their energy is not in it: identify from currents for them).

    Attributes
    ----------
    side : SensorSide
        Given as a SensorSide or its name (``"link"``, ``"motor"``); default link.
    offset : float
        What the sensor reads at zero torque, N m (identified with ``--target torque``); it is
        the sensor's, not the joint's: no energy or current includes it.
    """

    side: SensorSide = SensorSide.LINK
    offset: float = 0.0

    def __post_init__(self) -> None:
        side = checks.choice(self.side, SensorSide, "torque_sensor.side")
        object.__setattr__(self, "side", side)
        object.__setattr__(self, "offset", _number(self.offset, "torque_sensor.offset", low=None))

    @property
    def sees_rotor(self) -> bool:
        """Whether the rotors' inertia torque is in the reading (a motor-side sensor)."""
        return self.side == SensorSide.MOTOR


@dataclass(frozen=True, eq=False)
class Limits:
    """Joint limits, joint side.

    Attributes
    ----------
    position : ndarray, shape (2,)
        Lower and upper joint angle, rad.
    speed : float
        Maximum |qd|, rad/s.
    torque : float
        Maximum |tau|, N m.
    acceleration : float or None
        Maximum |qdd|, rad/s^2, where published.
    continuous : bool
        The joint turns without limit (no end stop: the UR3e's wrist 3): ``position`` is then
        the range a planner uses, and a logged angle beyond it is no error.
    """

    position: Array
    speed: float
    torque: float
    acceleration: float | None = None
    continuous: bool = False

    def __post_init__(self) -> None:
        if not isinstance(self.continuous, bool):
            raise KinergyError(f"limits.continuous must be true or false, got {self.continuous!r}")
        pos = _vector(self.position, 2, "limits.position")
        if not pos[0] < pos[1]:
            raise KinergyError(
                f"limits.position must be [lower, upper] with lower < upper, got {pos.tolist()}"
            )
        object.__setattr__(self, "position", pos)
        object.__setattr__(self, "speed", _number(self.speed, "limits.speed", low=0.0))
        object.__setattr__(self, "torque", _number(self.torque, "limits.torque", low=0.0))
        if self.acceleration is not None:
            object.__setattr__(
                self, "acceleration", _number(self.acceleration, "limits.acceleration", low=0.0)
            )


@dataclass(frozen=True, eq=False)
class Joint:
    """One revolute joint, the link it moves, its drive, limits and torque sensor.

    ``d``, ``a``, ``alpha``, ``offset`` follow the robot's convention (:data:`CONVENTIONS`); for
    ``mdh`` ``a`` and ``alpha`` are a_{i-1} and alpha_{i-1}. m and rad. ``torque_sensor`` says
    what a logged joint torque of this joint measures (:class:`TorqueSensor`; default a
    link-side sensor without offset).
    """

    name: str
    d: float
    a: float
    alpha: float
    offset: float
    link: Link
    drive: Drive
    limits: Limits
    torque_sensor: TorqueSensor = field(default_factory=TorqueSensor)

    def __post_init__(self) -> None:
        if not isinstance(self.name, str) or not self.name:
            raise KinergyError(f"joint name must be a non-empty string, got {self.name!r}")
        checks.plain_text(self.name, "joint name")
        if not isinstance(self.torque_sensor, TorqueSensor):
            raise KinergyError("torque_sensor must be a TorqueSensor")
        for name in ("d", "a", "alpha", "offset"):
            object.__setattr__(self, name, _number(getattr(self, name), name))


@dataclass(frozen=True)
class Source:
    """Where a group of parameters comes from: a status (:data:`SOURCE_STATUSES`) and a reference."""

    status: str
    ref: str = ""

    def __post_init__(self) -> None:
        if self.status not in SOURCE_STATUSES:
            raise KinergyError(
                f"source status must be one of {', '.join(SOURCE_STATUSES)}, got {self.status!r}"
            )


def _transform(value: Any, what: str) -> Array:
    arr = np.array(value, dtype=float)
    if arr.shape != (4, 4) or not np.all(np.isfinite(arr)):
        raise KinergyError(f"{what} must be a finite 4x4 homogeneous transform")
    rot = arr[:3, :3]
    if not np.allclose(rot @ rot.T, np.eye(3), atol=1e-9) or np.linalg.det(rot) < 0:
        raise KinergyError(f"{what} rotation must be a proper rotation matrix")
    if not np.allclose(arr[3], [0.0, 0.0, 0.0, 1.0]):
        raise KinergyError(f"{what} last row must be [0, 0, 0, 1]")
    arr.setflags(write=False)
    return arr


@dataclass(frozen=True)
class InputRecord:
    """One log a model was identified from, by content.

    Attributes
    ----------
    path : str
    sha256 : str
        Of the file's bytes (hex).
    size : int
        Bytes.
    rows : int
        Samples read.
    """

    path: str
    sha256: str
    size: int
    rows: int


@dataclass(frozen=True)
class Identified:
    """Where an identified model came from: the kinergy version, the command and its options,
    the logs by content, and the checks the user accepted (``--accept``)."""

    kinergy: str
    command: str
    options: Mapping[str, str | float | bool]
    inputs: tuple[InputRecord, ...]
    accepted: tuple[str, ...] = ()


@dataclass(frozen=True, eq=False)
class Robot:
    """A serial arm of revolute joints, as data.

    Attributes
    ----------
    name : str
    convention : Convention
        Given as a Convention or its name (``"dh"``, ``"mdh"``).
    joints : tuple of Joint, length n
    gravity : ndarray, shape (3,)
        Gravitational acceleration in the base frame, m/s^2 (default ``[0, 0, -9.81]``).
    payload : Payload or None
        Load at the flange.
    flange : ndarray, shape (4, 4)
        Pose of the flange in the last link frame (identity for UR arms, whose DH frame 6 is the
        flange).
    base : ndarray, shape (4, 4)
        Pose of the kinematic frame 0 in the robot's base frame (identity unless a file, e.g. an
        imported URDF, needs it). Gravity, forward kinematics and Jacobians are in the base frame.
    coupling : ndarray, shape (n, n)
        Transmission coupling: the motor-side input angles before the gears are
        ``coupling @ q`` (identity for independent joints; nursing eq 3 for differential joints).
    sources : mapping of str to Source
        Provenance of each parameter group (:data:`SOURCE_CATEGORIES`).
    description : str
    standby_power : float
        Constant power the arm's electronics and brakes draw from its supply whatever the
        motion, W (default 0: the seed's energy figures are the motors' alone; nominal until
        ``kinergy identify`` measures it from ``actual_robot_current``).
    bus_voltage : float
        DC bus voltage the joints are supplied from, V (48 V on UR e-Series).
    identified : Identified or None
        Where the model was identified from, when it was (``kinergy identify`` writes it).
    uncertainty : Uncertainty or None
        The identified parameters' errors (:mod:`kinergy.model.uncertainty`); None for a model
        that carries none (a built-in one, a data sheet).
    """

    name: str
    convention: Convention
    joints: tuple[Joint, ...]
    gravity: Array = field(default_factory=lambda: np.array([0.0, 0.0, -9.81]))
    payload: Payload | None = None
    flange: Array = field(default_factory=lambda: np.eye(4))
    base: Array = field(default_factory=lambda: np.eye(4))
    coupling: Array | None = None
    sources: Mapping[str, Source] = field(default_factory=dict)
    description: str = ""
    standby_power: float = 0.0
    bus_voltage: float = 48.0
    identified: Identified | None = None
    uncertainty: Uncertainty | None = None

    def __post_init__(self) -> None:
        if not isinstance(self.name, str) or not self.name:
            raise KinergyError(f"robot name must be a non-empty string, got {self.name!r}")
        object.__setattr__(
            self, "convention", checks.choice(self.convention, Convention, "convention")
        )
        checks.plain_text(self.name, "robot name")
        if isinstance(self.description, str):
            checks.plain_text(self.description, "robot description", breaks=True)
        joints = tuple(self.joints)
        if not joints:
            raise KinergyError("a robot needs at least one joint")
        for j in joints:
            if not isinstance(j, Joint):
                raise KinergyError(f"joints must be Joint objects, got {type(j).__name__}")
        names = [j.name for j in joints]
        dup = sorted({n for n in names if names.count(n) > 1})
        if dup:
            raise KinergyError(f"joint names must be unique; repeated: {', '.join(dup)}")
        object.__setattr__(self, "joints", joints)
        object.__setattr__(
            self,
            "standby_power",
            _number(self.standby_power, "standby_power", low=0.0, strict=False),
        )
        object.__setattr__(self, "bus_voltage", _number(self.bus_voltage, "bus_voltage", low=0.0))
        object.__setattr__(self, "gravity", _vector(self.gravity, 3, "gravity"))
        if self.payload is not None and not isinstance(self.payload, Payload):
            raise KinergyError("payload must be a Payload")
        object.__setattr__(self, "flange", _transform(self.flange, "flange"))
        object.__setattr__(self, "base", _transform(self.base, "base"))
        n = len(joints)
        try:
            coupling = np.eye(n) if self.coupling is None else np.array(self.coupling, dtype=float)
        except (TypeError, ValueError):  # ragged rows, text
            raise KinergyError(f"coupling must be a finite {n}x{n} matrix of numbers") from None
        if coupling.shape != (n, n) or not np.all(np.isfinite(coupling)):
            raise KinergyError(
                f"coupling must be a finite {n}x{n} matrix, got shape {coupling.shape}"
            )
        if abs(np.linalg.det(coupling)) < 1e-12:
            raise KinergyError("coupling matrix must be invertible")
        coupling.setflags(write=False)
        object.__setattr__(self, "coupling", coupling)
        sources = dict(self.sources)
        unknown = sorted(set(sources) - set(SOURCE_CATEGORIES))
        if unknown:
            raise KinergyError(
                f"unknown source categories: {', '.join(unknown)} "
                f"(known: {', '.join(SOURCE_CATEGORIES)})"
            )
        for cat in SOURCE_CATEGORIES:
            sources.setdefault(cat, Source("user"))
        object.__setattr__(self, "sources", sources)
        if self.uncertainty is not None and not _resolves(self, self.uncertainty):
            raise KinergyError(
                "uncertainty.parameters: names a parameter this robot does not have "
                f"({', '.join(self.uncertainty.parameters)})"
            )

    @property
    def n(self) -> int:
        """Number of joints."""
        return len(self.joints)

    @property
    def joint_names(self) -> list[str]:
        return [j.name for j in self.joints]

    def with_payload(self, payload: Payload | None) -> Robot:
        """A copy of this robot with ``payload`` at the flange (``None`` removes it)."""
        return dataclasses.replace(self, payload=payload)

    def with_joints(self, joints: Sequence[Joint]) -> Robot:
        """A copy of this robot with other joints (same count)."""
        if len(joints) != self.n:
            raise KinergyError(f"expected {self.n} joints, got {len(joints)}")
        out = dataclasses.replace(self, joints=tuple(joints), uncertainty=None)
        if self.uncertainty is not None and _resolves(out, self.uncertainty):
            out = dataclasses.replace(out, uncertainty=self.uncertainty)
        return out


def _resolves(robot: Robot, uncertainty: Uncertainty) -> bool:
    """Whether every parameter ``uncertainty`` names is one of ``robot``'s (a joint's friction
    family changed, its errors no longer apply: :meth:`Robot.with_joints` drops them)."""
    try:
        for name in uncertainty.parameters:
            parameter_value(robot, name)
    except (KinergyError, IndexError, KeyError):
        return False
    return True


def transmission_matrix(robot: Robot) -> Array:
    """``N = diag(gear_ratio) @ coupling``, shape (n, n): motor speeds = ``N @ qd`` (nursing eq 3
    for coupled joints; ``diag(gear_ratio)`` for independent ones)."""
    ratios = np.array([j.drive.gear_ratio for j in robot.joints])
    assert robot.coupling is not None
    return ratios[:, None] * robot.coupling
