"""What a friction model is: a name, its parameters, its torque and, where it is linear in some
parameters, its regressor columns.

A model is a :class:`FrictionModel` value; the registry (:mod:`kinergy.friction.registry`) names
them. All quantities are motor side: speed ``wm`` in rad/s, torques in N m.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, field

import numpy as np

from kinergy.arrays import Array
from kinergy.errors import KinergyError

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


@dataclass(frozen=True)
class FrictionModel:
    """One friction model.

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

    def __post_init__(self) -> None:
        bounds = {name: LEVEL_BOUNDS for name in self.linear}
        bounds.update(self.bounds)
        object.__setattr__(self, "bounds", bounds)
        if "smoothing" in self.parameters:
            object.__setattr__(self, "positive", self.positive | {"smoothing"})
            defaults = {"smoothing": SMOOTHING, **self.shape_defaults}
            object.__setattr__(self, "shape_defaults", defaults)
