"""Friction models of a joint drive, all on the motor side.

Each model is a name, the ordered names of its parameters, and a function of the motor speed
``wm`` (rad/s, motor side) and, where the model needs it, the load torque the drive delivers
(``tau_load``, N m, motor side; its sign together with the speed's gives the direction of power flow).
A robot file selects a model per joint in ``[joints.drive.friction]`` with ``model = "name"`` and
one entry per parameter.

Models
------
``none``
    No friction.
``viscous_coulomb``
    ``viscous * wm + coulomb * tanh(wm / smoothing)``.
``motor_reducer``
    Framework Table 1: motor viscous friction plus tanh-smoothed Coulomb friction of the motor and
    of the reducer, ``motor_viscous * wm + (motor_coulomb + reducer_coulomb) * tanh(wm / smoothing)``.
``power_flow``
    UR5e eqs 11-16: ``viscous * wm + tanh(wm / smoothing) * Tc`` with ``Tc = coulomb_direct`` when
    power flows from the motor to the load (``wm * tau_load > 0``) and ``coulomb_reverse`` otherwise.
``makkar``
    Nursing eq 13: ``gamma1 (tanh(gamma2 wm) - tanh(gamma3 wm)) + gamma4 tanh(gamma5 wm) + gamma6 wm``.
``stribeck``
    ``(coulomb + (static - coulomb) exp(-(wm / stribeck_speed)^2)) tanh(wm / smoothing) + viscous wm``.

Every model also takes an optional ``standstill`` (motor side, rad/s; default 0, off): while the
motor turns slower than that and accelerates less than ``STILL_RATE`` times that per second (it has
stopped, not passing through zero speed on a reversal), the friction keeps the value it had when
the joint last moved, scaled by ``holding`` (default 1; a stopped joint stays in stiction with
the direction it stopped in, and the position loop lets part of the torque relax, as real UR
joints do) instead of following the speed's noise through zero. It needs samples in time order.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping

import numpy as np
from numpy.typing import NDArray

from kinergy.errors import KinergyError

__all__ = [
    "FRICTION_MODELS",
    "LINEAR_PARAMETERS",
    "OPTIONAL_PARAMETERS",
    "check_friction",
    "friction_columns",
    "friction_torque",
    "hold_standstill",
    "linear_values",
    "start_parameters",
    "with_linear_parameters",
]

Array = NDArray[np.float64]


def _none(p: Mapping[str, float], wm: Array, tau_load: Array | None) -> Array:
    return np.zeros_like(wm)


def _viscous_coulomb(p: Mapping[str, float], wm: Array, tau_load: Array | None) -> Array:
    return p["viscous"] * wm + p["coulomb"] * np.tanh(wm / p["smoothing"])


def _motor_reducer(p: Mapping[str, float], wm: Array, tau_load: Array | None) -> Array:
    coulomb = p["motor_coulomb"] + p["reducer_coulomb"]
    return p["motor_viscous"] * wm + coulomb * np.tanh(wm / p["smoothing"])


def _power_flow(p: Mapping[str, float], wm: Array, tau_load: Array | None) -> Array:
    if tau_load is None:
        raise KinergyError(
            "friction model 'power_flow' needs the load torque to tell the direction of power flow"
        )
    direct = wm * tau_load > 0.0
    coulomb = np.where(direct, p["coulomb_direct"], p["coulomb_reverse"])
    return p["viscous"] * wm + coulomb * np.tanh(wm / p["smoothing"])


def _makkar(p: Mapping[str, float], wm: Array, tau_load: Array | None) -> Array:
    g1, g2, g3, g4, g5, g6 = (p[f"gamma{k}"] for k in range(1, 7))
    return g1 * (np.tanh(g2 * wm) - np.tanh(g3 * wm)) + g4 * np.tanh(g5 * wm) + g6 * wm


def _stribeck(p: Mapping[str, float], wm: Array, tau_load: Array | None) -> Array:
    level = p["coulomb"] + (p["static"] - p["coulomb"]) * np.exp(-((wm / p["stribeck_speed"]) ** 2))
    return level * np.tanh(wm / p["smoothing"]) + p["viscous"] * wm


_Eval = Callable[[Mapping[str, float], Array, Array | None], Array]

#: model name -> (ordered parameter names, evaluation function)
FRICTION_MODELS: dict[str, tuple[tuple[str, ...], _Eval]] = {
    "none": ((), _none),
    "viscous_coulomb": (("viscous", "coulomb", "smoothing"), _viscous_coulomb),
    "motor_reducer": (
        ("motor_viscous", "motor_coulomb", "reducer_coulomb", "smoothing"),
        _motor_reducer,
    ),
    "power_flow": (("viscous", "coulomb_direct", "coulomb_reverse", "smoothing"), _power_flow),
    "makkar": (tuple(f"gamma{k}" for k in range(1, 7)), _makkar),
    "stribeck": (("coulomb", "static", "stribeck_speed", "viscous", "smoothing"), _stribeck),
}

#: parameters that must be strictly positive (they divide)
_POSITIVE = {"smoothing", "stribeck_speed"}

#: optional parameters of every model and their defaults
OPTIONAL_PARAMETERS = {"standstill": 0.0, "holding": 1.0}
#: a motor is stopped when |wm| < standstill and |dwm| < STILL_RATE * standstill (1/s)
STILL_RATE = 100.0


def check_friction(model: str, params: Mapping[str, float]) -> dict[str, float]:
    """Validate a friction model name and its parameters; return them as plain floats.

    Raises
    ------
    KinergyError
        Unknown model, a missing or unknown parameter, a non-finite value, or a non-positive
        smoothing or Stribeck speed. The message names the model and the parameter.
    """
    if model not in FRICTION_MODELS:
        known = ", ".join(sorted(FRICTION_MODELS))
        raise KinergyError(f"unknown friction model {model!r} (known: {known})")
    required = FRICTION_MODELS[model][0]
    names = required + tuple(n for n in OPTIONAL_PARAMETERS if n in params)
    missing = [n for n in required if n not in params]
    if missing:
        raise KinergyError(
            f"friction model {model!r} is missing parameter(s): {', '.join(missing)}"
        )
    extra = sorted(set(params) - set(names))
    if extra:
        raise KinergyError(
            f"friction model {model!r} has unknown parameter(s): {', '.join(extra)} "
            f"(expected: {', '.join(names)})"
        )
    out: dict[str, float] = {}
    for name in names:
        value = params[name]
        if isinstance(value, bool) or not isinstance(value, int | float):
            raise KinergyError(f"friction parameter {name!r} must be a number, got {value!r}")
        if not np.isfinite(value):
            raise KinergyError(f"friction parameter {name!r} must be finite, got {value!r}")
        if name in _POSITIVE and value <= 0.0:
            raise KinergyError(f"friction parameter {name!r} must be > 0, got {value!r}")
        if name in OPTIONAL_PARAMETERS and value < 0.0:
            raise KinergyError(f"friction parameter {name!r} must be >= 0, got {value!r}")
        if name == "holding" and value > 1.0:
            raise KinergyError(f"friction parameter 'holding' must be <= 1, got {value!r}")
        out[name] = float(value)
    return out


def friction_torque(
    model: str,
    params: Mapping[str, float],
    wm: Array,
    tau_load: Array | None = None,
    dwm: Array | None = None,
) -> Array:
    """Friction torque on the motor side.

    Parameters
    ----------
    model : str
        One of :data:`FRICTION_MODELS`.
    params : mapping
        The model's parameters (see the module docstring), SI units, motor side.
    wm : array_like, shape (N,) or ()
        Motor speed, rad/s.
    tau_load : array_like, shape like ``wm``, optional
        Torque the motor delivers to the load without friction, N m, motor side. Needed by
        ``power_flow`` only (UR5e eqs 12-13).
    dwm : array_like, shape like ``wm``, optional
        Motor acceleration, rad/s^2; with ``standstill`` it tells a stop from a reversal.

    Returns
    -------
    ndarray, shape like ``wm``
        Friction torque, N m, opposing the motion (same sign as ``wm``).
    """
    fn = FRICTION_MODELS[model][1]
    wm = np.asarray(wm, dtype=float)
    load = None if tau_load is None else np.asarray(tau_load, dtype=float)
    if params.get("standstill", 0.0) > 0.0 and wm.ndim == 1:
        return friction_columns(model, params, wm, load, dwm) @ linear_values(model, params)
    return fn(params, wm, load)


#: For each model, the parameters it is linear in (the others, such as ``smoothing``, stay fixed
#: during a linear fit). ``motor_reducer``'s two Coulomb levels share one column: only their sum,
#: ``coulomb``, can be identified.
LINEAR_PARAMETERS: dict[str, tuple[str, ...]] = {
    "none": (),
    "viscous_coulomb": ("viscous", "coulomb"),
    "motor_reducer": ("motor_viscous", "coulomb"),
    "power_flow": ("viscous", "coulomb_direct", "coulomb_reverse"),
    "makkar": ("gamma1", "gamma4", "gamma6"),
    "stribeck": ("coulomb", "static", "viscous"),
}


def friction_columns(
    model: str,
    params: Mapping[str, float],
    wm: Array,
    tau_load: Array | None = None,
    dwm: Array | None = None,
) -> Array:
    """Regressor columns of a friction model: ``friction_torque == columns @ linear values``.

    The values are those named by :data:`LINEAR_PARAMETERS` (``motor_reducer``'s ``coulomb`` is
    ``motor_coulomb + reducer_coulomb``); the model's other parameters are taken from ``params``.
    For ``power_flow`` these are UR5e eq 18's columns ``[wm, tanh(wm_dir/e), tanh(wm_rev/e)]``.

    Parameters
    ----------
    wm : array_like, shape (N,)
        Motor speed, rad/s.
    tau_load : array_like, shape (N,), optional
        Load torque (motor side), needed by ``power_flow``.
    dwm : array_like, shape (N,), optional
        Motor acceleration, rad/s^2 (for ``standstill``).

    Returns
    -------
    ndarray, shape (N, k)
    """
    wm = np.asarray(wm, dtype=float)
    cols = _columns(model, params, wm, tau_load)
    threshold = params.get("standstill", 0.0)
    if threshold <= 0.0:
        return cols
    moving = np.abs(wm) >= threshold
    if dwm is not None:
        moving |= np.abs(np.asarray(dwm, dtype=float)) >= STILL_RATE * threshold
    held = params.get("holding", 1.0) * hold_standstill(cols, moving)
    return np.where(moving[:, None], cols, held)


def hold_standstill(columns: Array, moving: NDArray[np.bool_]) -> Array:
    """Rows where ``moving`` is False take the last moving row's values (zeros before the first).

    columns : (N, k); moving : (N,) bool, in time order.
    """
    index = np.where(moving, np.arange(moving.size), -1)
    np.maximum.accumulate(index, out=index)
    padded = np.vstack([np.zeros((1, columns.shape[1])), columns])
    return padded[index + 1]


def linear_values(model: str, params: Mapping[str, float]) -> Array:
    """The values of the model's :data:`LINEAR_PARAMETERS` (``motor_reducer``'s ``coulomb`` is the
    sum of its motor and reducer levels)."""
    if model == "motor_reducer":
        return np.array(
            [params["motor_viscous"], params["motor_coulomb"] + params["reducer_coulomb"]]
        )
    return np.array([params[name] for name in LINEAR_PARAMETERS[model]])


def _columns(model: str, params: Mapping[str, float], wm: Array, tau_load: Array | None) -> Array:
    p = params
    if model == "none":
        return np.zeros((wm.size, 0))
    if model in ("viscous_coulomb", "motor_reducer"):
        return np.column_stack([wm, np.tanh(wm / p["smoothing"])])
    if model == "power_flow":
        if tau_load is None:
            raise KinergyError("friction model 'power_flow' needs the load torque")
        flow = wm * np.asarray(tau_load, dtype=float)
        w_dir = np.where(flow > 0.0, wm, 0.0)  # UR5e eq 15
        w_rev = np.where(flow < 0.0, wm, 0.0)  # UR5e eq 16
        return np.column_stack(
            [wm, np.tanh(w_dir / p["smoothing"]), np.tanh(w_rev / p["smoothing"])]
        )
    if model == "makkar":
        return np.column_stack(
            [np.tanh(p["gamma2"] * wm) - np.tanh(p["gamma3"] * wm), np.tanh(p["gamma5"] * wm), wm]
        )
    if model == "stribeck":
        sign = np.tanh(wm / p["smoothing"])
        bump = np.exp(-((wm / p["stribeck_speed"]) ** 2))
        return np.column_stack([sign * (1.0 - bump), sign * bump, wm])
    raise KinergyError(f"unknown friction model {model!r}")


def with_linear_parameters(
    model: str, params: Mapping[str, float], values: Array
) -> dict[str, float]:
    """The model's parameters with the linear ones replaced by ``values`` (see
    :func:`friction_columns`). ``motor_reducer``'s fitted ``coulomb`` is shared between motor and
    reducer in the ratio of the old values (equally when both were zero)."""
    names = LINEAR_PARAMETERS[model]
    if len(values) != len(names):
        raise KinergyError(
            f"friction model {model!r} has {len(names)} linear parameters, got {len(values)}"
        )
    out = dict(params)
    for name, value in zip(names, values, strict=True):
        if model == "motor_reducer" and name == "coulomb":
            old = params["motor_coulomb"] + params["reducer_coulomb"]
            share = params["motor_coulomb"] / old if old > 0 else 0.5
            out["motor_coulomb"] = float(value) * share
            out["reducer_coulomb"] = float(value) * (1.0 - share)
        else:
            out[name] = float(value)
    return out


#: shape parameters a fit starts from when a joint switches friction model
_SHAPE_DEFAULTS = {
    "smoothing": 1e-3,
    "gamma2": 50.0,
    "gamma3": 5.0,
    "gamma5": 100.0,
    "stribeck_speed": 10.0,
    "motor_coulomb": 0.5,
    "reducer_coulomb": 0.5,
}


def start_parameters(
    model: str, current_model: str, current: Mapping[str, float]
) -> dict[str, float]:
    """Parameters to build a model's regressor columns with before a linear fit: the joint's own
    when the model is the same, else zero levels and default shape parameters (smoothing 1e-3
    rad/s, Makkar's and Stribeck's rates); a ``standstill`` hold is carried over."""
    if current_model == model:
        return dict(current)
    out = {name: _SHAPE_DEFAULTS.get(name, 0.0) for name in FRICTION_MODELS[model][0]}
    if "standstill" in current:
        out["standstill"] = current["standstill"]
    return out
