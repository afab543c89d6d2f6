"""The regression columns of the full method (:mod:`kinergy.identification.full`, its eq (1)).

Rows are the (sample, joint) pairs of every log, made chunk by chunk (:class:`Regression`);
columns, in this order:

- link base columns ``Y_b`` (nursing eqs 15-16; :meth:`BaseParameters.regressor`);
- reflected rotor inertias: motor ``m``'s column on joint ``j`` is ``N[m, j] (N qdd)_m``
  (UR5e eq 2, ``i^2 qdd`` for a UR joint);
- friction: ``N^T F(wm)``, ``F`` each motor's friction columns
  (:meth:`kinergy.friction.model.FrictionModel.friction_columns`) at the motor speeds ``wm = N qd``;
- against measured joint torques, each joint's torque sensor offset (N m): a column that is 1 on
  its own joint's rows and 0 elsewhere.

A link-side torque sensor (:class:`kinergy.model.robot.TorqueSensor`) does not see the rotors'
inertia torque (:func:`kinergy.predict.sensor_torque`): against measured torques, the rotor block
is zero on the rows of link-side joints, and a rotor column zero on every row is not an unknown
(:attr:`Columns.fixed`: the model's value is kept, and not reported as merged).

Against currents alone a common scale of every parameter and of the torque constants cannot be
told apart; :func:`scale_row` measures it against the model's published masses.

The ``power_flow`` model's columns depend on the direction of power flow through the gear, i.e.
on the sign of the load torque: :func:`power_flow_load` decides it from the measurement, and the
friction block is rebuilt for each decision (:meth:`Regression.rows`).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Iterator
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from kinergy.arrays import Array
from kinergy.drives.transmission import transmission_matrix
from kinergy.dynamics.regressor import BaseParameters, inertial_parameters, regressor
from kinergy.friction.model import FrictionModel
from kinergy.friction.none import MODEL as NO_FRICTION
from kinergy.friction.power_flow import MODEL as POWER_FLOW
from kinergy.friction.viscous_coulomb import MODEL as VISCOUS_COULOMB
from kinergy.identification.chunks import History, LogChunks
from kinergy.identification.drive_steps import _Signals, rotor_columns, signal_history
from kinergy.identification.options import Target
from kinergy.logs.prepare import IdentData
from kinergy.model.robot import Robot
from kinergy.predict import drive_state

__all__ = [
    "LOAD_DEPENDENT",
    "ROWS",
    "Columns",
    "Regression",
    "Rows",
    "columns",
    "joint_frictions",
    "power_flow_load",
    "scale_row",
    "sees_rotor",
]


#: friction models whose columns depend on the load torque (the direction of power flow)
LOAD_DEPENDENT = (POWER_FLOW,)
#: samples whose rows are made at a time (a chunk is cut into pieces of at most this many): the
#: rows of 8192 samples of a 6-joint arm with 60 columns take 24 MB
ROWS = 8192


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
    offset_at : int or None
        Against measured torques: joint ``j``'s sensor offset is column ``offset_at + j``
        (group ``"offset"``, N m); else None.
    fixed : ndarray of int
        Columns that are not unknowns, kept at the model's values: rotor inertias the target
        does not see (behind link-side torque sensors), and sensor offsets the logs do not
        determine (:mod:`kinergy.identification.offsets`).
    """

    names: list[str]
    group: list[str]
    prior: Array
    n_link: int
    fric_at: NDArray[np.intp]
    offset_at: int | None = None
    fixed: NDArray[np.intp] = dataclasses.field(default_factory=lambda: np.zeros(0, dtype=np.intp))

    def joint_of(self, k: int) -> int:
        """The joint (motor) of rotor or offset column ``k``, 0-based."""
        if self.group[k] == "offset":
            assert self.offset_at is not None
            return k - self.offset_at
        return k - self.n_link

    def friction(self, x: Array, m: int) -> Array:
        """Motor ``m``'s friction levels in the unknowns ``x`` (p,)."""
        return x[self.fric_at[m] : self.fric_at[m + 1]]


def joint_frictions(
    robot: Robot, friction: FrictionModel | None, commanded: bool
) -> tuple[list[FrictionModel], list[dict[str, float]]]:
    """Each motor's friction model in the regression and its starting parameters.

    ``friction`` replaces every joint's model (shape parameters from defaults unless the model is
    the joint's own); a joint without friction (``none``, e.g. a URDF without ``<dynamics>``)
    is fitted with Coulomb + viscous friction (framework Table 1): a real motion's torque has
    friction; against the commanded motion (``target_moment``, no friction) the models are
    ``none`` and the parameters the model's, kept.
    """
    models = [
        friction or (VISCOUS_COULOMB if model is NO_FRICTION else model)
        for model in (j.drive.friction.model for j in robot.joints)
    ]
    params = [
        model.start(j.drive.friction.model, j.drive.friction.params)
        for model, j in zip(models, robot.joints, strict=True)
    ]
    if commanded:
        return [NO_FRICTION] * robot.n, params
    return models, params


def sees_rotor(robot: Robot, target: Target) -> NDArray[np.bool_]:
    """Per joint, whether ``target`` carries the rotors' inertia torque (n,): measured torques
    only where the joint's sensor is on the motor side (:func:`kinergy.predict.sensor_torque`),
    the reference torques and the currents always."""
    if target != Target.TORQUE:
        return np.ones(robot.n, dtype=bool)
    return np.array([j.torque_sensor.sees_rotor for j in robot.joints])


def columns(
    robot: Robot,
    base: BaseParameters,
    models: list[FrictionModel],
    params: list[dict[str, float]],
    target: Target = Target.TORQUE,
) -> Columns:
    """Name, group and prior of every column: base parameters, rotor inertias, friction levels
    and, against measured torques (``target``), the sensors' offsets."""
    n = robot.n
    widths = [len(m.linear) for m in models]
    short = [base.names[k] for k in base.independent]
    joint = [f"joint {m + 1} ({j.name})" for m, j in enumerate(robot.joints)]
    offsets = target == Target.TORQUE
    prior = np.concatenate(
        [
            base.project(inertial_parameters(robot)),
            [j.drive.rotor_inertia for j in robot.joints],
            *[models[m].values_of(params[m]) for m in range(n)],
            [j.torque_sensor.offset for j in robot.joints] if offsets else [],
        ]
    )
    fric_at = base.size + n + np.cumsum([0, *widths])
    n_mat = transmission_matrix(robot)
    # motor m's rotor reaches joint j through N[m, j]: unseen when every such joint's sensor is
    # on the link side
    unseen = np.flatnonzero(~np.any((n_mat != 0.0) & sees_rotor(robot, target)[None, :], axis=1))
    return Columns(
        names=[f"base parameter {s}" for s in short]
        + [f"rotor inertia of {joint[m]}" for m in range(n)]
        + [f"friction {p} of {joint[m]}" for m in range(n) for p in models[m].linear]
        + ([f"torque sensor offset of {joint[j]}" for j in range(n)] if offsets else []),
        group=["link"] * base.size
        + ["rotor"] * n
        + ["friction"] * sum(widths)
        + ["offset"] * (n if offsets else 0),
        prior=prior,
        n_link=base.size,
        fric_at=fric_at,
        offset_at=int(fric_at[-1]) if offsets else None,
        fixed=(base.size + unseen).astype(np.intp),
    )


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


def power_flow_load(
    model: FrictionModel,
    params: dict[str, float],
    values: Array,
    signals: _Signals,
    skip: int,
    previous: Array,
) -> Array:
    """One motor's load torque (motor side, (N,)) that sets its friction's power-flow direction.

    The load is the measured motor torque less the friction, ``tau_load = tau_m - f`` (UR5e eqs
    12-17), and the friction depends on the direction: a sample is "direct" when
    ``wm (tau_m - f_direct) > 0`` and "reverse" when ``wm (tau_m - f_reverse) < 0``; where both or
    neither hold, ``previous`` decides. With the true friction this is the true direction whatever
    the link parameters, so iterating it with the fitted friction settles; iterating the fitted
    model's own load torque instead does not (near a load zero crossing the friction jumps by
    ``coulomb_direct - coulomb_reverse``, and small parameter errors flip samples that pull the
    fit further). Deciding by the measurement ties the regressor to the measurement's noise where
    the load is within the noise of zero: a small bias (:mod:`kinergy.identification.full`).

    Parameters
    ----------
    model, params, values :
        The motor's friction model, its parameters and its linear parameters' values.
    signals : _Signals
        Motor speeds, accelerations and the measured motor torque (``current``, N m) of the
        samples, the first ``skip`` of them those a friction held through standstill recalls
        (:class:`~kinergy.identification.chunks.History`).
    previous : ndarray, shape (N - skip,)
        The loads of the previous pass, N m, motor side.
    """
    w, acc = signals.wm, signals.dwm
    direction = np.sign(w)
    f_dir = model.friction_columns(params, w, direction, acc)[skip:] @ values
    f_rev = model.friction_columns(params, w, -direction, acc)[skip:] @ values
    w, meas = w[skip:], signals.current[skip:]
    load_dir, load_rev = meas - f_dir, meas - f_rev
    is_dir, is_rev = w * load_dir > 0.0, w * load_rev < 0.0
    return np.where(is_dir & ~is_rev, load_dir, np.where(is_rev & ~is_dir, load_rev, previous))


@dataclass(frozen=True, eq=False)
class Rows:
    """Eq (1)'s rows of some samples: the regressor ``a`` (N, n, p), the target as joint torques
    ``y3`` (N, n, N m), the positions regressed on ``q`` (N, n, rad), the motor speeds ``wm``
    (N, n, rad/s), and the friction's load torques before (``previous``) and as used
    (``load``), (N, n), N m motor side."""

    a: Array
    q: Array
    y3: Array
    wm: Array
    previous: Array
    load: Array


@dataclass(frozen=True, eq=False)
class Regression:
    """The full method's regression, eq (1) of :mod:`kinergy.identification.full`, over the logs'
    chunks: what its columns are and how a chunk's rows are made.

    Attributes
    ----------
    robot : Robot
        Kinematics, transmission, torque constants (against currents) and the model the first
        load torques come from.
    base : BaseParameters
    cols : Columns
    models, params : list
        Each motor's friction model and its parameters (:func:`joint_frictions`).
    target : Target
        ``MOMENT`` (on the commanded motion, no friction), ``TORQUE`` or ``CURRENT``.
    temperature : bool
        Every log has ``joint_temperatures`` (for temperature-dependent friction; else the
        models' reference temperature).
    """

    robot: Robot
    base: BaseParameters
    cols: Columns
    models: list[FrictionModel]
    params: list[dict[str, float]]
    target: Target
    temperature: bool

    @property
    def n_mat(self) -> Array:
        return transmission_matrix(self.robot)

    @property
    def n_fixed(self) -> int:
        """Columns before the friction block (link and rotor)."""
        return self.cols.n_link + self.robot.n

    @property
    def needs_load(self) -> bool:
        """Whether any friction model takes the load torque (``needs_load``)."""
        return any(m.needs_load for m in self.models)

    @property
    def own_load(self) -> list[int]:
        """The motors whose friction takes the load torque the fitted model gives itself
        (``load_coulomb``, ``load_thermal_power_law``: the link side's, which friction does
        not change)."""
        return [
            m
            for m, model in enumerate(self.models)
            if model not in LOAD_DEPENDENT and model.needs_load
        ]

    def motion(self, chunk: IdentData) -> tuple[Array, Array, Array]:
        """The motion regressed on: commanded against ``target_moment``, else the real one."""
        if self.target == Target.MOMENT:
            return chunk.q_cmd, chunk.qd_cmd, chunk.qdd_cmd
        return chunk.q, chunk.qd, chunk.qdd

    def torques(self, chunk: IdentData) -> Array:
        """The target as joint torques, (N, n) N m: ``N^T (k_t * I)`` for the current."""
        if self.target == Target.CURRENT:
            assert chunk.current is not None
            kt = np.array([j.drive.torque_constant for j in self.robot.joints])
            return np.asarray((chunk.current * kt) @ self.n_mat, dtype=float)
        y3 = chunk.tau_ref if self.target == Target.MOMENT else chunk.torque
        assert y3 is not None
        return np.asarray(y3, dtype=float)

    @property
    def sees_rotor(self) -> NDArray[np.bool_]:
        """Per joint, whether the target carries the rotors' inertia torque (:func:`sees_rotor`)."""
        return sees_rotor(self.robot, self.target)

    def histories(self) -> list[History[_Signals]]:
        """Per motor, what its friction held through standstill needs of earlier chunks."""
        return [signal_history(float(p.get("standstill", 0.0))) for p in self.params]

    def rows(
        self,
        logs: LogChunks,
        loads: Iterator[list[Array | None]] | None = None,
        x: Array | None = None,
    ) -> Iterator[tuple[int, Rows]]:
        """Eq (1)'s rows of every chunk, in pieces of at most :data:`ROWS` samples (segment
        number, :class:`Rows`).

        The friction's load torques: the model's (the first pass, ``loads`` None); those of
        a previous pass (``loads``: one record per piece, as ``Rows.load`` was) as they are; or,
        after a fit with unknowns ``x``, the next ones (:func:`power_flow_load` with the fitted
        friction for ``power_flow``, the fitted model's own load torque for the other
        load-dependent models)."""
        cols, n, n_fixed, n_mat = self.cols, self.robot.n, self.n_fixed, self.n_mat
        values = [cols.friction(cols.prior if x is None else x, m) for m in range(n)]
        histories = self.histories()
        for k, chunk in logs.chunks():
            for lo in range(0, len(chunk), ROWS):
                part = chunk.sliced(lo, min(lo + ROWS, len(chunk)))
                q, qd, qdd = self.motion(part)
                y3 = self.torques(part)
                tau_m = np.asarray(np.linalg.solve(n_mat.T, y3.T).T, dtype=float)
                wm, dwm = qd @ n_mat.T, qdd @ n_mat.T
                a = np.empty((len(part), n, cols.prior.size))
                a[:, :, : cols.n_link] = self.base.regressor(regressor(self.robot, q, qd, qdd))
                a[:, :, cols.n_link : n_fixed] = rotor_columns(n_mat, dwm)
                a[:, ~self.sees_rotor, cols.n_link : n_fixed] = 0.0  # link-side sensors
                if cols.offset_at is not None:
                    a[:, :, cols.offset_at :] = np.eye(n)[None, :, :]
                if not self.needs_load:
                    previous = np.zeros_like(q)
                elif loads is None:
                    previous = np.asarray(drive_state(self.robot, q, qd, qdd).tau_load)
                else:
                    (stored,) = next(loads)
                    assert stored is not None
                    previous = stored
                load = previous.copy()
                if x is not None and self.own_load:
                    tau_sim = a[:, :, :n_fixed] @ x[:n_fixed]
                    own = np.linalg.solve(n_mat.T, tau_sim.T).T
                    load[:, self.own_load] = own[:, self.own_load]
                temps = part.temperature if self.temperature else None
                col = n_fixed
                for m, model in enumerate(self.models):
                    temp = None if temps is None else temps[:, m]
                    signals = _Signals(previous[:, m], wm[:, m], dwm[:, m], tau_m[:, m], temp)
                    held, skip = histories[m].ahead(k, signals)
                    if model in LOAD_DEPENDENT and (loads is None or x is not None):
                        load[:, m] = power_flow_load(
                            model, self.params[m], values[m], held, skip, previous[:, m]
                        )
                    held = dataclasses.replace(
                        held, tau_load=np.concatenate([held.tau_load[:skip], load[:, m]])
                    )
                    width = len(model.linear)
                    if width:
                        f = model.friction_columns(
                            self.params[m],
                            held.wm,
                            held.tau_load,
                            held.dwm,
                            temperature=held.temperature,
                        )[skip:]
                        # motor m's friction reaches joint j through N[m, j]
                        a[:, :, col : col + width] = n_mat[m][None, :, None] * f[:, None, :]
                        col += width
                    histories[m].update(held, skip)
                yield k, Rows(a, q, y3, wm, previous, load)
