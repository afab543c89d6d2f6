"""The friction models by name, and the operations every caller uses on a joint's friction.

To add a model: write a module beside the others that defines ``MODEL = FrictionModel(...)``
(:mod:`kinergy.friction.model`) and list it in :data:`MODELS` below.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from kinergy.arrays import Array
from kinergy.errors import KinergyError
from kinergy.friction import (
    directional_power_law,
    load_coulomb,
    load_thermal_power_law,
    makkar,
    motor_reducer,
    none,
    power_flow,
    power_law,
    stribeck,
    thermal_viscous,
    viscous_coulomb,
)
from kinergy.friction.model import FrictionModel
from kinergy.friction.standstill import OPTIONAL_PARAMETERS, OPTIONAL_UNITS, hold

__all__ = [
    "MODELS",
    "check_friction",
    "friction_columns",
    "friction_torque",
    "get_model",
    "linear_values",
    "parameter_units",
    "start_parameters",
    "with_linear_parameters",
]


#: every friction model, by the name robot files use
MODELS: dict[str, FrictionModel] = {
    m.MODEL.name: m.MODEL
    for m in (
        none,
        viscous_coulomb,
        motor_reducer,
        power_flow,
        makkar,
        stribeck,
        power_law,
        directional_power_law,
        load_coulomb,
        thermal_viscous,
        load_thermal_power_law,
    )
}


def get_model(name: str) -> FrictionModel:
    """The model called ``name``; an unknown name is one line listing the known ones."""
    try:
        return MODELS[name]
    except (KeyError, TypeError):
        known = ", ".join(sorted(MODELS))
        raise KinergyError(f"unknown friction model {name!r} (known: {known})") from None


def parameter_units(model: str) -> dict[str, str]:
    """Every parameter a joint of ``model`` may have (the optional standstill ones last), with
    its unit, motor side: ``{"viscous": "N m s/rad", ..., "holding": "1"}``."""
    spec = get_model(model)
    return {**{name: spec.units.get(name, "") for name in spec.parameters}, **OPTIONAL_UNITS}


def check_friction(model: str, params: Mapping[str, float]) -> dict[str, float]:
    """Validate a friction model name and its parameters; return them as plain floats.

    Raises
    ------
    KinergyError
        Unknown model, a missing or unknown parameter, a non-finite value, or a non-positive
        smoothing or Stribeck speed. The message names the model and the parameter.
    """
    spec = get_model(model)
    required = spec.parameters
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
        if name in spec.positive and value <= 0.0:
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
    *,
    temperature: Array | None = None,
) -> Array:
    """Friction torque on the motor side.

    Parameters
    ----------
    model : str
        One of :data:`MODELS`.
    params : mapping
        The model's parameters (its module's docstring), SI units, motor side.
    wm : array_like, shape (N,) or ()
        Motor speed, rad/s.
    tau_load : array_like, shape like ``wm``, optional
        Torque the motor delivers to the load without friction, N m, motor side; needed by
        models with ``needs_load`` (``power_flow``: UR5e eqs 12-13).
    dwm : array_like, shape like ``wm``, optional
        Motor acceleration, rad/s^2; with ``standstill`` it tells a stop from a reversal.
    temperature : array_like, shape like ``wm``, optional
        The joint's temperature, deg C; needed by models with ``needs_temperature``.

    Returns
    -------
    ndarray, shape like ``wm``
        Friction torque, N m, opposing the motion (same sign as ``wm``).
    """
    spec = get_model(model)
    wm = np.asarray(wm, dtype=float)
    load, temp = _optional(tau_load), _optional(temperature)
    if params.get("standstill", 0.0) > 0.0 and wm.ndim == 1:
        columns = friction_columns(model, params, wm, load, dwm, temperature=temp)
        return columns @ linear_values(model, params)
    return spec.torque(params, wm, load, temp)


def _optional(x: Array | None) -> Array | None:
    return None if x is None else np.asarray(x, dtype=float)


def friction_columns(
    model: str,
    params: Mapping[str, float],
    wm: Array,
    tau_load: Array | None = None,
    dwm: Array | None = None,
    *,
    temperature: Array | None = None,
) -> Array:
    """Regressor columns of a friction model: ``friction_torque == columns @ linear values``.

    The values are the model's ``linear`` parameters (:func:`linear_values`); its other
    parameters are taken from ``params``. For ``power_flow`` these are UR5e eq 18's columns.

    Parameters
    ----------
    wm : array_like, shape (N,)
        Motor speed, rad/s.
    tau_load : array_like, shape (N,), optional
        Load torque (motor side), for models that need it.
    dwm : array_like, shape (N,), optional
        Motor acceleration, rad/s^2 (for ``standstill``).
    temperature : array_like, shape (N,), optional
        The joint's temperature, deg C, for models that need it.

    Returns
    -------
    ndarray, shape (N, k)
    """
    spec = get_model(model)
    if spec.columns is None:
        raise KinergyError(f"friction model {model!r} is not linear in any parameter")
    wm = np.asarray(wm, dtype=float)
    columns = spec.columns(params, wm, _optional(tau_load), _optional(temperature))
    return hold(params, columns, wm, dwm)


def linear_values(model: str, params: Mapping[str, float]) -> Array:
    """The values of the model's ``linear`` parameters, shape (k,)."""
    spec = get_model(model)
    return spec.linear_values(spec, params)


def with_linear_parameters(
    model: str, params: Mapping[str, float], values: Array
) -> dict[str, float]:
    """The model's parameters with the linear ones replaced by ``values`` (see
    :func:`friction_columns`)."""
    spec = get_model(model)
    if len(values) != len(spec.linear):
        raise KinergyError(
            f"friction model {model!r} has {len(spec.linear)} linear parameters, got {len(values)}"
        )
    return spec.with_linear(spec, params, np.asarray(values, dtype=float))


def start_parameters(
    model: str, current_model: str, current: Mapping[str, float]
) -> dict[str, float]:
    """Parameters to build a model's regressor columns with before a linear fit: the joint's own
    when the model is the same, else zero levels and the model's default shape parameters; a
    ``standstill`` hold is carried over."""
    if current_model == model:
        return dict(current)
    spec = get_model(model)
    out = {name: float(spec.shape_defaults.get(name, 0.0)) for name in spec.parameters}
    if "standstill" in current:
        out["standstill"] = current["standstill"]
    return out
