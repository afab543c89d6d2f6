"""What a friction model is: a name, its parameters, its torque and, where it is linear in some
parameters, its regressor columns; and the operations every caller uses on it.

A model is a :class:`FrictionModel` value, the type a family's name resolves to once, where it
enters (a robot file, an option: :func:`kinergy.friction.registry.get_model`); code below works
with the value and never looks a name up again. All quantities are motor side: speed ``wm`` in
rad/s, torques in N m.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, field

import numpy as np

from kinergy import checks
from kinergy.arrays import Array
from kinergy.errors import Code, KinergyError
from kinergy.friction.standstill import OPTIONAL_PARAMETERS, OPTIONAL_UNITS, hold

__all__ = ["LEVEL_BOUNDS", "SMOOTHING", "Columns", "FrictionModel", "Torque", "needed"]

#: the smoothing speed ``smoothing`` of ``tanh(wm / smoothing)``, rad/s, that models start from:
#: far below any motion's motor speed, so the tanh is a sign but for a moment at each reversal
SMOOTHING = 1e-3
#: the range of a linear parameter a model gives none for: a friction level, >= 0 (motor side)
LEVEL_BOUNDS = (0.0, np.inf)


#: ``torque(params, wm, tau_load, temperature) -> (N,)``: friction torque, motor side, N m.
#: ``tau_load`` (N m, motor side) and ``temperature`` (deg C, the joint's) may be None when the
#: model does not need them.
Torque = Callable[[Mapping[str, float], Array, Array | None, Array | None], Array]
#: ``columns(params, wm, tau_load, temperature) -> (N, k)``: ``torque == columns @ linear values``.
Columns = Callable[[Mapping[str, float], Array, Array | None, Array | None], Array]


def needed(signal: Array | None, model: str, what: str) -> Array:
    """``signal`` as a float array; a model that cannot do without it says so in one line."""
    if signal is None:
        raise KinergyError(f"friction model {model!r} needs {what}")
    return np.asarray(signal, dtype=float)


def _by_name(model: FrictionModel, params: Mapping[str, float]) -> Array:
    return np.array([params[name] for name in model.linear], dtype=float)


def _replace_by_name(
    model: FrictionModel, params: Mapping[str, float], values: Array
) -> dict[str, float]:
    out = dict(params)
    out.update({name: float(v) for name, v in zip(model.linear, values, strict=True)})
    return out


def _optional(x: Array | None) -> Array | None:
    return None if x is None else np.asarray(x, dtype=float)


@dataclass(frozen=True, eq=False, repr=False)
class FrictionModel:
    """One friction model (one per family: compared by identity).

    Attributes
    ----------
    name : str
        The name robot files use (``model = "power_flow"``).
    parameters : tuple of str
        Its parameters, in file order; all required.
    torque : callable
        ``torque(params, wm, tau_load, temperature) -> ndarray (N,)``, opposing the motion.
    linear : tuple of str
        The parameters the torque is linear in (fitted by least squares; the others, such as
        ``smoothing``, shape the columns and stay fixed in a linear fit). A name not in
        ``parameters`` is a combination that :attr:`linear_values` defines.
    columns : callable or None
        ``columns(params, wm, tau_load, temperature) -> ndarray (N, len(linear))`` with
        ``torque == columns @ linear_values(params)``.
    positive : frozenset of str
        Parameters that must be > 0 (they divide); ``smoothing`` always is.
    bounds : mapping of str to (float, float)
        Physically plausible range of each linear parameter (motor side), for constrained fits;
        a linear parameter not named here is a level, in :data:`LEVEL_BOUNDS`.
    shape_defaults : mapping of str to float
        Values a fit starts the non-linear parameters from when a joint switches to this model;
        ``smoothing`` starts from :data:`SMOOTHING` unless named here.
    needs_load : bool
        Whether ``torque`` needs the load torque (power-flow or load-dependent friction).
    needs_temperature : bool
        Whether ``torque`` uses the joint temperature (temperature-dependent friction; without
        one such a model is evaluated at its ``reference_temperature``).
    search : mapping of str to (float, float)
        Shape parameters that fits find by a 1-D search inside these bounds (``power_law``'s
        ``exponent``); the linear parameters are solved for at every trial value.
    citation : str
        Where the model comes from (``UR5e eqs 11-16``).
    units : mapping of str to str
        Each parameter's unit (motor side), as tables print it: ``{"viscous": "N m s/rad"}``.
    linear_values, with_linear : callable, optional
        How :attr:`linear` maps to and from the parameters, when not one to one by name.
    line : callable or None
        For a family that is a Coulomb level plus a viscous term (its Coulomb term smoothed by
        ``tanh(wm / smoothing)``): ``line(params) -> (coulomb, viscous)`` (N m, N m s/rad),
        what the URDF and MJCF exports write for it exactly (:mod:`kinergy.model.friction_line`).
    """

    name: str
    parameters: tuple[str, ...]
    torque: Torque
    linear: tuple[str, ...] = ()
    columns: Columns | None = None
    positive: frozenset[str] = frozenset()
    bounds: Mapping[str, tuple[float, float]] = field(default_factory=dict)
    shape_defaults: Mapping[str, float] = field(default_factory=dict)
    needs_load: bool = False
    needs_temperature: bool = False
    search: Mapping[str, tuple[float, float]] = field(default_factory=dict)
    citation: str = ""
    units: Mapping[str, str] = field(default_factory=dict)
    linear_values: Callable[[FrictionModel, Mapping[str, float]], Array] = _by_name
    with_linear: Callable[[FrictionModel, Mapping[str, float], Array], dict[str, float]] = (
        _replace_by_name
    )
    line: Callable[[Mapping[str, float]], tuple[float, float]] | None = None

    def __post_init__(self) -> None:
        bounds = {name: LEVEL_BOUNDS for name in self.linear}
        bounds.update(self.bounds)
        object.__setattr__(self, "bounds", bounds)
        if "smoothing" in self.parameters:
            object.__setattr__(self, "positive", self.positive | {"smoothing"})
            defaults = {"smoothing": SMOOTHING, **self.shape_defaults}
            object.__setattr__(self, "shape_defaults", defaults)

    def __repr__(self) -> str:
        return f"FrictionModel({self.name!r})"

    def __str__(self) -> str:
        return self.name

    def parameter_units(self) -> dict[str, str]:
        """Every parameter a joint of this model may have (the optional standstill ones last),
        with its unit, motor side: ``{"viscous": "N m s/rad", ..., "holding": "1"}``."""
        return {**{name: self.units.get(name, "") for name in self.parameters}, **OPTIONAL_UNITS}

    def check(self, params: Mapping[str, object]) -> dict[str, float]:
        """This model's parameters, checked, as plain floats.

        Raises
        ------
        KinergyError
            A missing or unknown parameter, a value that is not a finite number, a non-positive
            smoothing or Stribeck speed, a negative standstill or holding, a holding above 1.
            The message names the model and the parameter.
        """
        names = self.parameters + tuple(n for n in OPTIONAL_PARAMETERS if n in params)
        missing = [n for n in self.parameters if n not in params]
        if missing:
            raise KinergyError(
                f"friction model {self.name!r} is missing parameter(s): {', '.join(missing)}",
                Code.MISSING,
            )
        extra = sorted(set(params) - set(names))
        if extra:
            raise KinergyError(
                f"friction model {self.name!r} has unknown parameter(s): {', '.join(extra)} "
                f"(expected: {', '.join(names)})",
                Code.UNKNOWN_KEY,
            )
        bounds: dict[str, dict[str, float]] = {
            **{name: {"gt": 0.0} for name in self.positive},
            **{name: {"ge": 0.0} for name in OPTIONAL_PARAMETERS},
            "holding": {"ge": 0.0, "le": 1.0},
        }
        return {
            name: checks.number(
                params[name], f"friction parameter {name!r}", **bounds.get(name, {})
            )
            for name in names
        }

    def friction_torque(
        self,
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
        wm = np.asarray(wm, dtype=float)
        load, temp = _optional(tau_load), _optional(temperature)
        if params.get("standstill", 0.0) > 0.0 and wm.ndim == 1:
            columns = self.friction_columns(params, wm, load, dwm, temperature=temp)
            return columns @ self.values_of(params)
        return self.torque(params, wm, load, temp)

    def friction_columns(
        self,
        params: Mapping[str, float],
        wm: Array,
        tau_load: Array | None = None,
        dwm: Array | None = None,
        *,
        temperature: Array | None = None,
    ) -> Array:
        """Regressor columns: ``friction_torque == columns @ values_of(params)``.

        The values are the model's ``linear`` parameters; its other parameters are taken from
        ``params``. For ``power_flow`` these are UR5e eq 18's columns.

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
        if self.columns is None:
            raise KinergyError(f"friction model {self.name!r} is not linear in any parameter")
        wm = np.asarray(wm, dtype=float)
        columns = self.columns(params, wm, _optional(tau_load), _optional(temperature))
        return hold(params, columns, wm, dwm)

    def values_of(self, params: Mapping[str, float]) -> Array:
        """The values of the model's ``linear`` parameters, shape (k,)."""
        return self.linear_values(self, params)

    def with_values(self, params: Mapping[str, float], values: Array) -> dict[str, float]:
        """``params`` with the linear ones replaced by ``values`` (k,) (see
        :meth:`friction_columns`)."""
        if len(values) != len(self.linear):
            raise KinergyError(
                f"friction model {self.name!r} has {len(self.linear)} linear parameters, got "
                f"{len(values)}"
            )
        return self.with_linear(self, params, np.asarray(values, dtype=float))

    def start(
        self, current: FrictionModel | None = None, params: Mapping[str, float] | None = None
    ) -> dict[str, float]:
        """Parameters to build this model's columns with before a linear fit, on a joint whose
        friction is ``current`` with ``params``: the joint's own when the model is the same, else
        zero levels and this model's default shape parameters; a ``standstill`` hold is carried
        over."""
        params = params or {}
        if current is self:
            return dict(params)
        out = {name: float(self.shape_defaults.get(name, 0.0)) for name in self.parameters}
        if "standstill" in params:
            out["standstill"] = params["standstill"]
        return out
