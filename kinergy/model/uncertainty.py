"""What an identified model knows about its own errors, and the 95 % intervals that follow.

An identified robot carries :class:`Uncertainty`: for the parameters its logs identified (a
joint's ``rotor_inertia``, ``torque_constant`` and friction levels, the arm's ``standby_power``),
``K`` error *modes* ``D`` (K, p), one row per delete-one-block jackknife replicate of the
identification (:mod:`kinergy.identification.uncertainty`), so that the parameter covariance is::

    Sigma = D^T D,    D_k = sqrt((K - 1) / K) (theta_(k) - mean_k theta_(k))

and any figure ``E(theta)`` the model predicts has, to first order (the delta method),::

    var E = |D g|^2,    g = dE/dtheta (p,)

with the 95 % interval ``E +- t_{0.975, nu} c sqrt(var E)`` (``nu`` the jackknife's degrees of
freedom ``K - 1``, ``c`` the calibration factor, 1 unless the model file says otherwise). A
difference of two figures from the same model (a program against its optimised version) takes
``g_1 - g_2``: errors the two share cancel. A model that carries no uncertainty (a built-in
one, a data sheet) has none to give: :func:`interval` returns None and the output says so,
never a zero-width interval.

Parameters are named ``joints[i].rotor_inertia``, ``joints[i].torque_constant``,
``joints[i].friction.NAME`` (i from 0) and ``standby_power``; :func:`perturbed` returns the robot
with one of them moved, which is how gradients are taken (:mod:`kinergy.accounting.uncertainty`).
"""

from __future__ import annotations

import dataclasses
import re
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from kinergy.arrays import Array
from kinergy.checks import integer, number
from kinergy.errors import KinergyError

if TYPE_CHECKING:
    from kinergy.model.robot import Robot

__all__ = [
    "LEVEL",
    "Interval",
    "Uncertainty",
    "interval",
    "parameter_value",
    "perturbed",
    "t_quantile",
    "uncertainty_from_dict",
    "uncertainty_to_dict",
]

#: the coverage every interval kinergy prints aims at
LEVEL = 0.95
_NAME = re.compile(
    r"^(?:standby_power|joints\[(\d+)\]\.(rotor_inertia|torque_constant|friction\.\w+))$"
)


@dataclass(frozen=True, eq=False)
class Uncertainty:
    """A model's parameter errors as error modes (module docstring).

    Attributes
    ----------
    parameters : tuple of str, length p
        The parameters' names (module docstring).
    modes : ndarray, shape (K, p)
        Error modes in the parameters' units: ``modes.T @ modes`` is their covariance.
    dof : int
        Degrees of freedom of the interval's t quantile (the jackknife's ``K - 1``).
    method : str
        How the modes were made, for the user (``"jackknife over 10 time blocks"``).
    calibration : float
        Factor on every standard deviation (1: the jackknife's own).
    """

    parameters: tuple[str, ...]
    modes: Array
    dof: int
    method: str
    calibration: float = 1.0

    def __post_init__(self) -> None:
        modes = np.atleast_2d(np.asarray(self.modes, dtype=float))
        object.__setattr__(self, "modes", modes)
        object.__setattr__(self, "parameters", tuple(self.parameters))
        if modes.shape[1] != len(self.parameters):
            raise KinergyError(
                f"uncertainty.modes: rows must have {len(self.parameters)} values (one per "
                f"parameter), got {modes.shape[1]}"
            )
        for name in self.parameters:
            if not _NAME.match(name):
                raise KinergyError(f"uncertainty.parameters: unknown parameter {name!r}")
        if not np.all(np.isfinite(modes)):
            raise KinergyError("uncertainty.modes: must be finite numbers")
        object.__setattr__(self, "dof", integer(self.dof, "uncertainty.dof", ge=1))
        calibration = number(self.calibration, "uncertainty.calibration", gt=0.0)
        object.__setattr__(self, "calibration", calibration)

    @property
    def covariance(self) -> Array:
        """``modes.T @ modes`` (p, p), in the parameters' units squared."""
        return np.asarray(self.modes.T @ self.modes)

    @property
    def std(self) -> Array:
        """Each parameter's standard deviation (p,)."""
        return np.sqrt(np.sum(self.modes**2, axis=0))

    def spread(self, gradient: Array) -> float:
        """The standard deviation of a figure with ``gradient`` dE/dtheta (p,):
        ``calibration |modes @ gradient|``."""
        return float(self.calibration * np.linalg.norm(self.modes @ np.asarray(gradient)))

    def of_joints(self, joints: Sequence[int]) -> Uncertainty:
        """Only the parameters of ``joints`` and the arm's."""
        keep = [k for k, p in enumerate(self.parameters) if _joint_of(p) in (None, *joints)]
        return dataclasses.replace(
            self, parameters=tuple(self.parameters[k] for k in keep), modes=self.modes[:, keep]
        )


@dataclass(frozen=True)
class Interval:
    """A figure's 95 % interval from the model's uncertainty: ``low``, ``high`` and the standard
    deviation ``std`` (the figure's units), ``level`` (0.95) and how it was made (``method``)."""

    low: float
    high: float
    std: float
    level: float
    method: str

    @property
    def half_width(self) -> float:
        return 0.5 * (self.high - self.low)

    def holds(self, value: float) -> bool:
        return self.low <= value <= self.high


def t_quantile(dof: int, level: float = LEVEL) -> float:
    """The two-sided ``level`` quantile of Student's t with ``dof`` degrees of freedom."""
    from scipy import stats  # heavy: loaded only when an interval is made

    return float(stats.t.ppf(0.5 + 0.5 * level, dof))


def interval(uncertainty: Uncertainty | None, value: float, gradient: Array) -> Interval | None:
    """``value``'s 95 % interval (module docstring) for its gradient (p,) over the parameters of
    ``uncertainty``; None when the model carries no uncertainty."""
    if uncertainty is None:
        return None
    std = uncertainty.spread(gradient)
    half = t_quantile(uncertainty.dof) * std
    method = f"delta method over the model's parameter errors ({uncertainty.method})"
    return Interval(value - half, value + half, std, LEVEL, method)


def _joint_of(name: str) -> int | None:
    match = _NAME.match(name)
    assert match is not None
    return None if match.group(1) is None else int(match.group(1))


def parameter_value(robot: Robot, name: str) -> float:
    """The value of parameter ``name`` (module docstring) in ``robot``."""
    match = _NAME.match(name)
    if match is None:
        raise KinergyError(f"unknown parameter {name!r}")
    if match.group(1) is None:
        return float(robot.standby_power)
    drive = robot.joints[int(match.group(1))].drive
    what = match.group(2)
    if what == "rotor_inertia":
        return float(drive.rotor_inertia)
    if what == "torque_constant":
        return float(drive.torque_constant)
    return float(drive.friction.params[what.removeprefix("friction.")])


def perturbed(robot: Robot, moves: dict[str, float]) -> Robot:
    """``robot`` with each parameter of ``moves`` (name -> change, its units) moved: a rotor
    inertia through its motor inertia, a torque constant with the motor constant kept (as
    identification writes it), a friction level in its friction's parameters."""
    from kinergy.model.robot import Friction  # the robot module imports this one

    joints = list(robot.joints)
    standby = robot.standby_power
    for name, delta in moves.items():
        match = _NAME.match(name)
        if match is None:
            raise KinergyError(f"unknown parameter {name!r}")
        if match.group(1) is None:
            standby += delta
            continue
        i, what = int(match.group(1)), match.group(2)
        drive = joints[i].drive
        if what == "rotor_inertia":
            drive = dataclasses.replace(drive, motor_inertia=drive.motor_inertia + delta)
        elif what == "torque_constant":
            drive = dataclasses.replace(drive, torque_constant=drive.torque_constant + delta)
        else:
            params = dict(drive.friction.params)
            key = what.removeprefix("friction.")
            params[key] = params[key] + delta
            drive = dataclasses.replace(drive, friction=Friction(drive.friction.model, params))
        joints[i] = dataclasses.replace(joints[i], drive=drive)
    return dataclasses.replace(robot.with_joints(joints), standby_power=standby)


def uncertainty_to_dict(u: Uncertainty) -> dict[str, Any]:
    """The ``[uncertainty]`` table of a robot file."""
    return {
        "method": u.method,
        "dof": u.dof,
        "calibration": u.calibration,
        "parameters": list(u.parameters),
        "std": u.std.tolist(),
        "modes": u.modes.tolist(),
    }


def uncertainty_from_dict(data: Any) -> Uncertainty:
    """:class:`Uncertainty` from the ``[uncertainty]`` table (``std`` is for readers: the modes
    give it)."""
    where = "uncertainty"
    if not isinstance(data, dict):
        raise KinergyError(f"{where}: must be a table")
    unknown = set(data) - {"method", "dof", "calibration", "parameters", "std", "modes"}
    if unknown:
        raise KinergyError(f"{where}: unknown key {sorted(unknown)[0]!r}")
    for key in ("parameters", "modes", "dof"):
        if key not in data:
            raise KinergyError(f"{where}.{key}: missing")
    params, modes = data["parameters"], data["modes"]
    if not isinstance(params, list) or not all(isinstance(p, str) for p in params):
        raise KinergyError(f"{where}.parameters: must be an array of strings")
    try:
        array = np.array(modes, dtype=float)
    except (TypeError, ValueError):
        raise KinergyError(f"{where}.modes: must be an array of arrays of numbers") from None
    if array.ndim != 2:
        raise KinergyError(f"{where}.modes: must be an array of arrays of numbers")
    return Uncertainty(
        parameters=tuple(params),
        modes=array,
        dof=data["dof"] if isinstance(data["dof"], int) else -1,
        method=str(data.get("method", "")),
        calibration=float(data.get("calibration", 1.0)),
    )
