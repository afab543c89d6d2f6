"""A drive's friction as a Coulomb level and a viscous coefficient: what URDF and MJCF hold.

URDF's ``<dynamics damping friction>`` and MuJoCo's ``damping`` and ``frictionloss`` describe a
joint's friction by two numbers, a viscous coefficient and a Coulomb level. kinergy's friction
families (:mod:`kinergy.friction.registry`, motor side) are richer: a Coulomb level that depends on
the direction of power flow (``power_flow``, UR5e eqs 11-16), on the load or the temperature, a
power of the speed, a Stribeck or Makkar hump (nursing eq 13). :func:`friction_line` gives a motor's
best line ::

    f(w, L) ~ c sign(w) + b w,        c >= 0 (N m),  b >= 0 (N m s/rad),  motor side

by non-negative least squares over a fixed grid (the same on every host):

- motor speeds ``w``: 100 values evenly spaced from ``w_max / 100`` to ``w_max`` in each direction,
  ``w_max`` the fastest the motor turns with every joint at its speed limit
  (:func:`motor_ranges`). A robot file does not record the speeds seen when it was identified, so
  the joints' speed limits set the range. Speeds below ``w_max / 100`` are left out: there every
  family's ``tanh(w / smoothing)`` turns over, which no line follows and which URDF and MuJoCo
  regularise in their own ways;
- motor loads ``L`` (the torque the motor delivers to the load without friction, the
  ``tau_load`` of :func:`kinergy.predict.drive_state`): 10 values evenly spaced from ``-L_max`` to
  ``L_max``, ``L_max`` the largest motor torque the joints' torque limits allow. Half the grid has
  power flowing from motor to load, half the other way, so a ``power_flow`` line's Coulomb level is
  the mean of ``coulomb_direct`` and ``coulomb_reverse``; a load-dependent level is taken at the
  grid's mean ``|L|``;
- temperature: none, so a temperature-dependent family is taken at its ``reference_temperature``;
- the optional standstill hold (``standstill``, ``holding``) is not part of a line: MuJoCo's
  ``frictionloss`` holds a stopped joint by itself.

A family that is a Coulomb level plus a viscous term (``viscous_coulomb``, ``motor_reducer``: its
:attr:`~kinergy.friction.model.FrictionModel.line`) is not fitted: its line is its own Coulomb
level and viscous coefficient, exactly, whatever its ``tanh(wm / smoothing)`` does near zero speed
(URDF's ``friction`` and MuJoCo's ``frictionloss`` are a Coulomb level that each tool regularises
in its own way). Any other family is fitted; where it is a line over that grid (``power_flow``
with equal levels, ``power_law`` with exponent 1, ...) the fit is exact (to rounding). Either way
:attr:`FrictionLine.exact` is True; otherwise the fit's RMS and largest error over the grid say
how far the line is from the model.

Referred to the joints through ``N = diag(gear_ratio) @ coupling`` (the transmission matrix of
:mod:`kinergy.drives.transmission`; ``wm = N qd``, ``tau = N^T tau_m``), the motors' lines give the
joint torque ``N^T (c * sign(N qd)) + N^T diag(b) N qd``. For a joint with its own motor
(``coupling = I``) that is ``|n| c sign(qd) + n^2 b qd``: URDF's ``friction = |n| c`` and
``damping = n^2 b``, with ``n`` the gear ratio.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from kinergy.arrays import Array
from kinergy.errors import KinergyError
from kinergy.model.robot import Friction, Robot, transmission_matrix

__all__ = [
    "LOADS",
    "SPEEDS",
    "SPEED_FLOOR",
    "FrictionLine",
    "JointSide",
    "friction_line",
    "friction_lines",
    "joint_side",
    "motor_ranges",
]

#: speeds per direction of the grid
SPEEDS = 100
#: the grid's slowest speed as a fraction of its fastest
SPEED_FLOOR = 0.01
#: loads of the grid (an even count: no load of exactly zero, half of each sign)
LOADS = 10
#: the largest friction torque a line is fitted to, N m (a robot file allows 1e6 N m of friction
#: parameters; far beyond any drive)
MAGNITUDE = 1e12
#: a line whose largest error is below this fraction of the model's largest friction is exact
EXACT = 1e-9


@dataclass(frozen=True)
class FrictionLine:
    """The best Coulomb + viscous line of one motor's friction (motor side).

    Attributes
    ----------
    coulomb : float
        c, N m, >= 0.
    viscous : float
        b, N m s/rad, >= 0.
    speed : float
        ``w_max``, rad/s: the grid's fastest motor speed.
    load : float
        ``L_max``, N m: the grid's largest motor load.
    rms_error, max_error : float
        RMS and largest ``|f - line|`` over the grid, N m (for a Coulomb + viscous family, what
        its ``tanh`` smoothing takes off the Coulomb level there).
    rms_friction : float
        RMS of the model's friction over the grid, N m.
    exact : bool
        Whether the line is the family's own (a Coulomb + viscous family), or the fit's largest
        error is below 1e-9 of the largest friction.
    """

    coulomb: float
    viscous: float
    speed: float
    load: float
    rms_error: float
    max_error: float
    rms_friction: float
    exact: bool

    @property
    def relative_error(self) -> float:
        """``rms_error / rms_friction`` (0 without friction)."""
        return self.rms_error / self.rms_friction if self.rms_friction > 0.0 else 0.0


def motor_ranges(robot: Robot) -> tuple[Array, Array]:
    """The grid's range per motor: fastest speed and largest load, motor side.

    Returns
    -------
    speed : ndarray, shape (n,)
        ``w_max_k = sum_j |N_kj| v_j`` (rad/s), ``v_j`` joint j's speed limit: motor k's speed with
        every joint at its limit, in the directions that add up.
    load : ndarray, shape (n,)
        ``L_max_k = sum_j |(N^-T)_kj| T_j`` (N m), ``T_j`` joint j's torque limit: the largest motor
        torque ``tau_m = N^-T tau`` for joint torques within their limits.
    """
    n_mat = transmission_matrix(robot)
    speed_limits = np.array([j.limits.speed for j in robot.joints])
    torque_limits = np.array([j.limits.torque for j in robot.joints])
    speed = np.abs(n_mat) @ speed_limits
    load = np.abs(np.linalg.inv(n_mat.T)) @ torque_limits
    return speed, load


def _grid(load: float) -> tuple[Array, Array]:
    """Motor speeds as fractions of ``w_max`` and loads (N m) of the fit, each shape
    (2 SPEEDS LOADS,)."""
    one_way = np.linspace(SPEED_FLOOR, 1.0, SPEEDS)
    speeds = np.concatenate([-one_way[::-1], one_way])
    loads = np.linspace(-load, load, LOADS)
    u, tau = np.meshgrid(speeds, loads, indexing="ij")
    return u.ravel(), tau.ravel()


def friction_line(friction: Friction, speed: float, load: float) -> FrictionLine:
    """The best line ``c sign(w) + b w`` (``c, b >= 0``) of one motor's friction over the grid of
    the module docstring.

    Parameters
    ----------
    friction : Friction
        The motor's friction model and parameters (motor side).
    speed : float
        ``w_max``, rad/s, > 0.
    load : float
        ``L_max``, N m, > 0.

    Returns
    -------
    FrictionLine
    """
    from scipy.optimize import nnls  # heavy (0.2 s): imported on first use

    u, tau_load = _grid(load)
    if friction.model.line is not None:  # Coulomb + viscous: its own levels, not a fit
        coulomb, viscous = friction.model.line(friction.params)
        f = np.asarray(friction.model.torque(friction.params, u * speed, tau_load, None))
        residual = f - (coulomb * np.sign(u) + viscous * speed * u)  # the smoothing's alone
        return FrictionLine(
            coulomb=float(coulomb),
            viscous=float(viscous),
            speed=float(speed),
            load=float(load),
            rms_error=float(np.sqrt(np.mean(residual**2))),
            max_error=float(np.max(np.abs(residual))),
            rms_friction=float(np.sqrt(np.mean(f**2))),
            exact=True,
        )
    with np.errstate(all="ignore"):  # a non-finite torque is refused below
        f = np.asarray(
            friction.model.torque(friction.params, u * speed, tau_load, None), dtype=float
        )
    columns = np.column_stack([np.sign(u), u])  # unknowns c and b w_max: both columns O(1)
    if not np.all(np.isfinite(f)) or float(np.max(np.abs(f))) > MAGNITUDE:
        raise KinergyError(
            f"friction model {friction.name!r} has no finite Coulomb + viscous line over motor "
            f"speeds up to {speed:g} rad/s and loads up to {load:g} N m"
        )
    solution, _ = nnls(columns, f)
    coulomb, viscous = float(solution[0]), float(solution[1] / speed)
    if not np.isfinite(viscous):
        raise KinergyError(
            f"friction model {friction.name!r}: a motor speed range of {speed:g} rad/s is too "
            "small for a viscous coefficient"
        )
    residual = f - columns @ solution
    largest = float(np.max(np.abs(f)))
    max_error = float(np.max(np.abs(residual)))
    return FrictionLine(
        coulomb=coulomb,
        viscous=viscous,
        speed=float(speed),
        load=float(load),
        rms_error=float(np.sqrt(np.mean(residual**2))),
        max_error=max_error,
        rms_friction=float(np.sqrt(np.mean(f**2))),
        exact=max_error <= EXACT * largest,
    )


def friction_lines(
    robot: Robot, ranges: tuple[Array, Array] | None = None
) -> tuple[FrictionLine, ...]:
    """:func:`friction_line` of every motor of ``robot``, over its :func:`motor_ranges` (or the
    ``(speed, load)`` of ``ranges``, each shape (n,): a file's record of the grid)."""
    speed, load = motor_ranges(robot) if ranges is None else ranges
    lines = []
    for joint, s, lo in zip(robot.joints, speed, load, strict=True):
        try:
            lines.append(friction_line(joint.drive.friction, float(s), float(lo)))
        except KinergyError as exc:
            raise exc.prefixed(f"joint {joint.name!r}") from None
    return tuple(lines)


@dataclass(frozen=True)
class JointSide:
    """A robot's drives referred to its joints (see the module docstring).

    Attributes
    ----------
    transmission : ndarray, shape (n, n)
        ``N = diag(gear_ratio) @ coupling``.
    lines : tuple of FrictionLine, length n
        Each motor's friction line, motor side.
    reflected : ndarray, shape (n, n)
        ``N^T diag(J_m + J_r) N``, kg m^2.
    viscous : ndarray, shape (n, n)
        ``N^T diag(b) N``, N m s/rad.
    armature, damping, friction : ndarray, shape (n,)
        A joint's own share: the diagonals of ``reflected`` and ``viscous`` (kg m^2,
        N m s/rad) and ``sum_k |N_kj| c_k`` (N m).
    coupled : bool
        Whether ``coupling`` is not the identity.
    """

    transmission: Array
    lines: tuple[FrictionLine, ...]
    reflected: Array
    viscous: Array
    armature: Array
    damping: Array
    friction: Array
    coupled: bool


def joint_side(robot: Robot, ranges: tuple[Array, Array] | None = None) -> JointSide:
    """The drives of ``robot`` referred to its joints (the friction lines over ``ranges``, see
    :func:`friction_lines`)."""
    n_mat = transmission_matrix(robot)
    lines = friction_lines(robot, ranges)
    rotor = np.array([j.drive.rotor_inertia for j in robot.joints])
    b = np.array([line.viscous for line in lines])
    c = np.array([line.coulomb for line in lines])
    reflected = n_mat.T @ (rotor[:, None] * n_mat)
    viscous = n_mat.T @ (b[:, None] * n_mat)
    assert robot.coupling is not None
    return JointSide(
        transmission=n_mat,
        lines=lines,
        reflected=reflected,
        viscous=viscous,
        armature=np.diag(reflected).copy(),
        damping=np.diag(viscous).copy(),
        friction=np.abs(n_mat).T @ c,
        coupled=not np.array_equal(robot.coupling, np.eye(robot.n)),
    )
