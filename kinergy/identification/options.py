"""What an identification is asked to do, as types: parsed once where the user's options enter
(the command line, the Python API) and passed down as they are.

Examples
--------
>>> IdentifyOptions(method=Method.FULL, target="current").target
<Target.CURRENT: 'current'>
"""

from __future__ import annotations

import enum
from dataclasses import dataclass

from kinergy.checks import choice, number
from kinergy.errors import KinergyError
from kinergy.friction.registry import MODELS

__all__ = [
    "AUTO",
    "FILTER_CUTOFF",
    "MAX_RIDGE",
    "CurrentOptions",
    "Hold",
    "IdentifyOptions",
    "MakkarMethod",
    "Method",
    "NursingOptions",
    "Solver",
    "Target",
]

#: ``friction``: per joint, the model with the lowest cross-validated current RMS
AUTO = "auto"
#: the largest ridge weight taken
MAX_RIDGE = 1e12


class Method(enum.StrEnum):
    """Identification methods: the UR5e doc's sequential procedure, the full base-parameter
    regression, the coupled-drive nursing arm's pipeline."""

    SEQUENTIAL = "sequential"
    FULL = "full"
    NURSING = "nursing"


class Target(enum.StrEnum):
    """What the full method regresses against: ``target_moment``, currents or measured joint
    torques; ``auto`` the first of those the logs have."""

    AUTO = "auto"
    MOMENT = "moment"
    CURRENT = "current"
    TORQUE = "torque"


class Solver(enum.StrEnum):
    """Least squares of the full method: ordinary, weighted (per joint by its residual spread),
    ridge."""

    OLS = "ols"
    WLS = "wls"
    RIDGE = "ridge"


class Hold(enum.Enum):
    """How much of its friction a stopped joint holds through standstill, as the current fit
    tries it (:mod:`kinergy.identification.sequential`): each fraction of
    :data:`~kinergy.identification.drive_steps.HOLDINGS`, keeping whichever explains the currents best
    (``SEARCH``), none (the UR5e doc's model) or all of it."""

    SEARCH = "search"
    NONE = "none"
    FULL = "full"


def _check_friction(friction: str | None) -> None:
    if friction is not None and friction != AUTO and friction not in MODELS:
        known = ", ".join([*sorted(MODELS), AUTO])
        raise KinergyError(f"--friction: unknown model {friction!r}; known: {known}")


@dataclass(frozen=True)
class CurrentOptions:
    """What the torque constants and friction are fitted with on the currents (UR5e eqs 17-18).

    Attributes
    ----------
    friction : str or None
        A friction model of the registry for every joint, :data:`AUTO` (per joint, the model
        with the lowest cross-validated current RMS) or None (each joint's own model).
    hold : Hold
    """

    friction: str | None = None
    hold: Hold = Hold.SEARCH

    def __post_init__(self) -> None:
        _check_friction(self.friction)

    @property
    def auto(self) -> bool:
        return self.friction == AUTO


@dataclass(frozen=True)
class IdentifyOptions:
    """The options of an identification, checked on construction (a name given for an enum is
    parsed into it): one line naming the option.

    Attributes
    ----------
    method : Method
    friction : str or None
        A friction model of the registry (:data:`kinergy.friction.registry.MODELS`) for every
        joint, :data:`AUTO`, or None: each joint's own model.
    target : Target
        Full method only.
    solver : Solver
        Full method only.
    ridge : float
        The ridge weight (``solver`` ridge), from 0 to :data:`MAX_RIDGE`.
    """

    method: Method = Method.SEQUENTIAL
    friction: str | None = None
    target: Target = Target.AUTO
    solver: Solver = Solver.OLS
    ridge: float = 0.0

    def record(self) -> dict[str, str | float]:
        """The options as a model file records them (``friction`` only when given)."""
        out: dict[str, str | float] = {"method": self.method.value}
        if self.friction is not None:
            out["friction"] = self.friction
        out.update(target=self.target.value, solver=self.solver.value, ridge=self.ridge)
        return out

    def __post_init__(self) -> None:
        object.__setattr__(self, "method", choice(self.method, Method, "--method"))
        object.__setattr__(self, "target", choice(self.target, Target, "--target"))
        object.__setattr__(self, "solver", choice(self.solver, Solver, "--solver"))
        _check_friction(self.friction)
        object.__setattr__(self, "ridge", number(self.ridge, "--ridge", ge=0.0, le=MAX_RIDGE))


#: the nursing doc's low-pass cutoff for the motor currents, Hz
FILTER_CUTOFF = 15.0


class MakkarMethod(enum.StrEnum):
    """How the nursing method fits Makkar's friction curve (nursing eq 13): least squares or
    the doc's particle swarm."""

    LSQ = "lsq"
    PSO = "pso"


@dataclass(frozen=True)
class NursingOptions:
    """The options of the nursing method (:func:`kinergy.identification.nursing.nursing`).

    Attributes
    ----------
    eta : float
        Nursing eq 21's efficiency (the twin: 1; the doc's robot: 0.82).
    fit : MakkarMethod
    period : float or None
        The excitation's period, s; None: found from each log.
    cutoff : float or None
        The currents' low-pass cutoff, Hz (the doc's 15); None: not filtered.
    split : float
        The share of the excitation samples (in time) that trains the ridge regression, in
        (0, 1].
    alphas : tuple of float or None
        The ridge weights tried (default ``logspace(-12, 0, 49)``).
    trim : int
        Samples dropped at each end of a constant-speed run.
    seed : int
        The particle swarm's seed.
    """

    eta: float = 1.0
    fit: MakkarMethod = MakkarMethod.LSQ
    period: float | None = None
    cutoff: float | None = FILTER_CUTOFF
    split: float = 0.7
    alphas: tuple[float, ...] | None = None
    trim: int = 10
    seed: int = 0
