"""A first-order thermal model of each joint: warmed by its drive's losses, cooled to ambient.

Each joint is one heat capacity ``C`` (J/K) connected to the ambient air through one thermal
resistance ``R_th`` (K/W) (:class:`kinergy.model.robot.Thermal`)::

    C dT/dt = P_loss - (T - T_ambient) / R_th,        P_loss = R I^2 + tau_f wm + P_standby / n

heated by the copper loss of its motor (UR5e eq 21's ``R I^2``, the equivalent DC motor), the
friction its drive dissipates (``tau_f wm``, motor side, >= 0 for friction that opposes the
motion) and its share of the arm's standby power: what the arm draws from its supply for its
electronics and brakes (:mod:`kinergy.drives.bus`) is turned into heat in the arm, where each
UR joint carries its own drive electronics and brake; the ``n`` joints take equal shares. Over a
sample the losses are held; the step is then exact::

    T_k = T_amb + (T_{k-1} - T_amb) a + R_th P_{k-1} (1 - a),      a = exp(-dt / (R_th C))

A UR joint's time constant ``R_th C`` is tens of minutes, so a long run warms its joints by
ten to twenty kelvin and, through temperature-dependent friction (``thermal_viscous``, Raviola et
al. 2021), lowers its friction: the framework doc's "thermal effects" (section 5).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from kinergy.arrays import Array
from kinergy.drives.electrics import winding_resistances
from kinergy.errors import KinergyError
from kinergy.model.robot import Robot, Thermal

__all__ = ["joint_losses", "joint_temperatures", "thermal_models"]


def thermal_models(robot: Robot) -> list[Thermal]:
    """Every joint's :class:`~kinergy.model.robot.Thermal`.

    Raises
    ------
    KinergyError
        A joint has none (naming it).
    """
    missing = [j.name for j in robot.joints if j.drive.thermal is None]
    if missing:
        raise KinergyError(
            f"{robot.name}: no thermal model for joint(s) {', '.join(missing)} "
            "([joints.drive.thermal] capacity and resistance)"
        )
    return [j.drive.thermal for j in robot.joints if j.drive.thermal is not None]


def joint_losses(
    robot: Robot,
    current: ArrayLike,
    tau_friction: ArrayLike,
    wm: ArrayLike,
    *,
    standby: float = 0.0,
) -> Array:
    """Heat each joint makes, ``R I^2 + tau_f wm + standby / n`` (W), shape (N, n).

    Parameters
    ----------
    current : array_like, shape (N, n)
        Motor currents, A.
    tau_friction, wm : array_like, shape (N, n)
        Friction torque (N m) and speed (rad/s), motor side; friction that opposes the motion
        heats the joint, the product is clipped at 0.
    standby : float
        The arm's standby power, W (its electronics and brakes, ``Robot.standby_power``), shared
        equally by the joints (module docstring); 0: the drives' losses alone.
    """
    i = np.asarray(current, dtype=float)
    friction = np.maximum(np.asarray(tau_friction, dtype=float) * np.asarray(wm, dtype=float), 0.0)
    heat = winding_resistances(robot) * i**2 + friction + standby / robot.n
    return np.asarray(heat, dtype=float)


def _step(t: Array, losses: Array, x0: float, capacity: float, resistance: float) -> Array:
    """``T - T_amb`` of one joint over ``t`` (module docstring), from ``x0`` at ``t[0]``."""
    from scipy.signal import lfilter  # slow to import; only the thermal model needs it

    dt = np.diff(t)
    tau = capacity * resistance
    out = np.empty(t.size)
    out[0] = x0
    if dt.size == 0:
        return out
    if np.allclose(dt, dt[0], rtol=1e-6, atol=0.0):
        a = float(np.exp(-dt[0] / tau))
        y, _ = lfilter([(1.0 - a) * resistance], [1.0, -a], losses[:-1], zi=[a * x0])
        out[1:] = y
        return out
    a_k = np.exp(-dt / tau)
    for k in range(1, t.size):  # irregular time stamps: the same step, one at a time
        out[k] = out[k - 1] * a_k[k - 1] + resistance * losses[k - 1] * (1.0 - a_k[k - 1])
    return out


def joint_temperatures(
    robot: Robot,
    t: ArrayLike,
    losses: ArrayLike,
    *,
    ambient: float = 25.0,
    initial: float | ArrayLike | None = None,
) -> Array:
    """Joint temperatures (deg C) over a run with the given losses (module docstring).

    Parameters
    ----------
    robot : Robot
        Every joint needs a thermal model (``[joints.drive.thermal]``).
    t : array_like, shape (N,)
        Increasing time stamps, s.
    losses : array_like, shape (N, n)
        Heat made in each joint, W (:func:`joint_losses`).
    ambient : float
        Air temperature, deg C.
    initial : float or array_like of shape (n,), optional
        Joint temperatures at ``t[0]``, deg C; default ``ambient`` (a cold start).

    Returns
    -------
    ndarray, shape (N, n)
    """
    models = thermal_models(robot)
    t = np.asarray(t, dtype=float)
    p = np.asarray(losses, dtype=float)
    start = np.broadcast_to(ambient if initial is None else initial, (robot.n,)).astype(float)
    out = np.empty_like(p)
    for j, model in enumerate(models):
        rise = _step(t, p[:, j], start[j] - ambient, model.capacity, model.resistance)
        out[:, j] = ambient + rise
    return out
