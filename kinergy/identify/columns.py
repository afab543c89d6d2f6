"""The stacked regression columns of the full method (:mod:`kinergy.identify.full`, its eq (1)).

Rows are the (sample, joint) pairs of every log, stacked; columns, in this order:

- link base columns ``Y_b`` (nursing eqs 15-16; :meth:`BaseParameters.regressor`);
- reflected rotor inertias: motor ``m``'s column on joint ``j`` is ``N[m, j] (N qdd)_m``
  (UR5e eq 2, ``i^2 qdd`` for a UR joint);
- friction: ``N^T F(wm)``, ``F`` each motor's friction columns
  (:func:`kinergy.friction.registry.friction_columns`) at the motor speeds ``wm = N qd``.

Against currents alone a common scale of every parameter and of the torque constants cannot be
told apart; :func:`scale_row` measures it against the model's published masses.

The ``power_flow`` model's columns depend on the direction of power flow through the gear, i.e.
on the sign of the load torque: :func:`power_flow_load` decides it from the measurement, and the
friction block is rebuilt for each decision (:func:`set_friction`).
"""

from __future__ import annotations

import itertools
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from kinergy.arrays import Array
from kinergy.drives.transmission import transmission_matrix
from kinergy.dynamics.regressor import BaseParameters, inertial_parameters, regressor
from kinergy.friction.registry import (
    friction_columns,
    get_model,
    linear_values,
    start_parameters,
)
from kinergy.model.robot import Robot

__all__ = [
    "LOAD_DEPENDENT",
    "Columns",
    "Stacked",
    "columns",
    "joint_frictions",
    "power_flow_load",
    "rotor_columns",
    "scale_row",
    "set_friction",
    "stack",
]


#: friction models whose columns depend on the load torque (the direction of power flow)
LOAD_DEPENDENT = ("power_flow",)


@dataclass(frozen=True)
class Columns:
    """What each column of the stacked regression is: [link base | rotor | friction].

    Attributes
    ----------
    names : list of str
        One line per column (``"base parameter Iyy1"``, ``"rotor inertia of joint 1 (...)"``, ...).
    group : list of str
        ``"link"``, ``"rotor"`` or ``"friction"`` per column.
    prior : ndarray, shape (p,)
        The model's value of every unknown (base parameters, kg m^2 motor side, friction levels).
    n_link : int
        Number of link base columns ``b``; the rotor columns follow, one per motor.
    fric_at : ndarray of int, shape (n + 1,)
        Motor ``m``'s friction columns are ``fric_at[m]:fric_at[m + 1]``.
    """

    names: list[str]
    group: list[str]
    prior: Array
    n_link: int
    fric_at: NDArray[np.intp]

    def friction(self, x: Array, m: int) -> Array:
        """Motor ``m``'s friction levels in the unknowns ``x`` (p,)."""
        return x[self.fric_at[m] : self.fric_at[m + 1]]


def rotor_columns(n_mat: Array, dwm: Array) -> Array:
    """Reflected rotor inertia columns, shape (N, n, n): motor ``m``'s column on joint ``j`` is
    ``N[m, j] (N qdd)_m`` (UR5e eq 2), ``dwm = qdd N^T`` (N, n) the motor accelerations, rad/s^2;
    times ``J`` (kg m^2, motor side) they give joint torques ``N^T diag(J) N qdd``."""
    return n_mat.T[None, :, :] * dwm[:, None, :]


def joint_frictions(
    robot: Robot, friction: str | None, commanded: bool
) -> tuple[list[str], list[dict[str, float]]]:
    """Each motor's friction model in the regression and its starting parameters.

    ``friction`` replaces every joint's model (shape parameters from defaults unless the model is
    the joint's own); against the commanded motion (``target_moment``, no friction) the models are
    ``"none"`` and the parameters the model's, kept.
    """
    params = [
        start_parameters(
            friction or j.drive.friction.model, j.drive.friction.model, j.drive.friction.params
        )
        for j in robot.joints
    ]
    if commanded:
        return ["none"] * robot.n, params
    return [friction or j.drive.friction.model for j in robot.joints], params


def columns(
    robot: Robot,
    base: BaseParameters,
    models: list[str],
    params: list[dict[str, float]],
) -> Columns:
    """Name, group and prior of every column: base parameters, rotor inertias, friction levels."""
    n = robot.n
    widths = [len(get_model(m).linear) for m in models]
    short = [base.names[k] for k in base.independent]
    joint = [f"joint {m + 1} ({j.name})" for m, j in enumerate(robot.joints)]
    prior = np.concatenate(
        [
            base.project(inertial_parameters(robot)),
            [j.drive.rotor_inertia for j in robot.joints],
            *[linear_values(models[m], params[m]) for m in range(n)],
        ]
    )
    return Columns(
        names=[f"base parameter {s}" for s in short]
        + [f"rotor inertia of {joint[m]}" for m in range(n)]
        + [f"friction {p} of {joint[m]}" for m in range(n) for p in get_model(models[m]).linear],
        group=["link"] * base.size + ["rotor"] * n + ["friction"] * sum(widths),
        prior=prior,
        n_link=base.size,
        fric_at=base.size + n + np.cumsum([0, *widths]),
    )


@dataclass(frozen=True, eq=False)
class Stacked:
    """The full method's regression over every log; ``N`` samples, ``n`` joints, ``p`` columns.

    Attributes
    ----------
    cols : Columns
    models, params : list
        Each motor's friction model and its parameters (:func:`joint_frictions`).
    n_mat : ndarray, shape (n, n)
        Transmission matrix, motor speeds ``wm = N qd``.
    q, qd, qdd : ndarray, shape (N, n)
        The motion regressed on (rad, rad/s, rad/s^2).
    a : ndarray, shape (N, n, p)
        Regressor, rows (sample, joint); the friction block is filled by :func:`set_friction`.
    y3 : ndarray, shape (N, n)
        The target as joint torques, N m.
    tau_m : ndarray, shape (N, n)
        The target as motor torques, N m (``N^-T y3``).
    wm, dwm : ndarray, shape (N, n)
        Motor speeds (rad/s) and accelerations (rad/s^2).
    starts : ndarray of int
        Log boundaries in the samples.
    temperature : ndarray, shape (N, n), or None
        ``joint_temperatures`` (deg C) where every log has them, for temperature-dependent
        friction; None: the models' reference temperature.
    """

    cols: Columns
    models: list[str]
    params: list[dict[str, float]]
    n_mat: Array
    q: Array
    qd: Array
    qdd: Array
    a: Array
    y3: Array
    tau_m: Array
    wm: Array
    dwm: Array
    starts: NDArray[np.intp]
    temperature: Array | None = None

    @property
    def a_flat(self) -> Array:
        """The regressor as a matrix, shape (N n, p) (a view of :attr:`a`)."""
        return self.a.reshape(-1, self.a.shape[2])

    @property
    def y(self) -> Array:
        """The target, shape (N n,)."""
        return self.y3.reshape(-1)

    @property
    def n_fixed(self) -> int:
        """Columns before the friction block (link and rotor)."""
        return self.cols.n_link + self.n_mat.shape[0]

    @property
    def needs_load(self) -> bool:
        """Whether any friction model takes the load torque (``needs_load`` in the registry)."""
        return any(get_model(m).needs_load for m in self.models)

    @property
    def needs_flow(self) -> bool:
        """Whether any friction model depends on the direction of power flow (``power_flow``)."""
        return any(m in LOAD_DEPENDENT for m in self.models)


def scale_row(robot: Robot, base: BaseParameters, q: Array) -> Array:
    """How the link base parameters scale the model's gravity torques, shape (b,).

    With ``G(q) = Y_b(q, 0, 0)`` the base columns at rest and ``g0 = G pi_b,model`` the model's
    gravity torques (N m) at the poses ``q`` (N, n), the row is ``sum(g0 * G) / |g0|^2``: its
    product with base parameters is their gravity torques projected on the model's, 1 for the
    model (the scale the model's published masses set).
    """
    step = max(1, q.shape[0] // 2000)  # the gravity torques of a few thousand poses suffice
    qs = q[::step]
    at_rest = base.regressor(regressor(robot, qs, np.zeros_like(qs), np.zeros_like(qs)))
    g0 = at_rest @ base.project(inertial_parameters(robot))
    return np.asarray(np.einsum("sj,sjb->b", g0, at_rest) / float(np.sum(g0**2)))


def stack(
    robot: Robot,
    base: BaseParameters,
    cols: Columns,
    frictions: tuple[list[str], list[dict[str, float]]],
    motion: tuple[Array, Array, Array],
    y3: Array,
    lengths: Sequence[int],
    temperature: Array | None = None,
) -> Stacked:
    """The link base and rotor columns of ``motion`` (q, qd, qdd, each (N, n)); the friction
    block is left to :func:`set_friction`. ``y3`` (N, n) is the target as joint torques, N m;
    ``lengths`` the samples of each log; ``temperature`` (N, n) deg C or None."""
    q, qd, qdd = motion
    n, samples, n_link = robot.n, q.shape[0], cols.n_link
    n_mat = transmission_matrix(robot)
    a = np.empty((samples, n, cols.prior.size))
    a[:, :, :n_link] = base.regressor(regressor(robot, q, qd, qdd))
    wm, dwm = qd @ n_mat.T, qdd @ n_mat.T
    a[:, :, n_link : n_link + n] = rotor_columns(n_mat, dwm)
    tau_m = np.asarray(np.linalg.solve(n_mat.T, y3.T).T, dtype=float)
    starts = np.cumsum([0, *lengths])
    return Stacked(cols, *frictions, n_mat, q, qd, qdd, a, y3, tau_m, wm, dwm, starts, temperature)


def set_friction(stacked: Stacked, load: Array) -> None:
    """Fill ``stacked.a``'s friction block, joint side ``N^T F`` (N, n, k), in place, for the load
    torques ``load`` (N, n, motor side).

    Columns are built log by log (``stacked.starts`` bounds them) so friction held through
    standstill sees each log's samples in time order.
    """
    n_mat, models, params, temps = (
        stacked.n_mat,
        stacked.models,
        stacked.params,
        stacked.temperature,
    )
    col = stacked.n_fixed
    for m, model in enumerate(models):
        width = len(get_model(model).linear)
        if width == 0:
            continue
        f = np.vstack(
            [
                friction_columns(
                    model,
                    params[m],
                    stacked.wm[a:b, m],
                    load[a:b, m],
                    stacked.dwm[a:b, m],
                    temperature=None if temps is None else temps[a:b, m],
                )
                for a, b in itertools.pairwise(stacked.starts)
            ]
        )
        # motor m's friction reaches joint j through N[m, j]
        stacked.a[:, :, col : col + width] = n_mat[m][None, :, None] * f[:, None, :]
        col += width


def power_flow_load(stacked: Stacked, values: list[Array], previous: Array) -> Array:
    """Load torques (motor side, (N, n)) that set the friction's power-flow direction.

    The load is the measured motor torque less the friction, ``tau_load = tau_m - f`` (UR5e eqs
    12-17), and the friction depends on the direction: a sample is "direct" when
    ``wm (tau_m - f_direct) > 0`` and "reverse" when ``wm (tau_m - f_reverse) < 0``; where both or
    neither hold, ``previous`` decides. With the true friction this is the true direction whatever
    the link parameters, so iterating it with the fitted friction settles; iterating the fitted
    model's own load torque instead does not (near a load zero crossing the friction jumps by
    ``coulomb_direct - coulomb_reverse``, and small parameter errors flip samples that pull the
    fit further). Deciding by the measurement ties the regressor to the measurement's noise where
    the load is within the noise of zero: a small bias (:mod:`kinergy.identify.full`).

    Parameters
    ----------
    stacked : Stacked
        Motor speeds, accelerations and measured motor torques (``tau_m``), log boundaries.
    values : list of ndarray
        Each motor's friction levels (the model's ``linear`` parameters, :mod:`kinergy.friction`).
    previous : ndarray, shape (N, n)
        The loads of the previous pass, N m, motor side.
    """
    out = previous.copy()
    for m, model in enumerate(stacked.models):
        if model not in LOAD_DEPENDENT:
            continue
        for a, b in itertools.pairwise(stacked.starts):
            w, acc = stacked.wm[a:b, m], stacked.dwm[a:b, m]
            meas, params = stacked.tau_m[a:b, m], stacked.params[m]
            direction = np.sign(w)
            load_dir = meas - friction_columns(model, params, w, direction, acc) @ values[m]
            load_rev = meas - friction_columns(model, params, w, -direction, acc) @ values[m]
            is_dir, is_rev = w * load_dir > 0.0, w * load_rev < 0.0
            out[a:b, m] = np.where(
                is_dir & ~is_rev, load_dir, np.where(is_rev & ~is_dir, load_rev, previous[a:b, m])
            )
    return out
