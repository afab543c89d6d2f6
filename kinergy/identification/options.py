"""What an identification is asked to do, as types: parsed once where the user's options enter
(the command line, the Python API) and passed down as they are.

Examples
--------
>>> IdentifyOptions(method=Method("full"), target=Target("current")).method
<Method.FULL: 'full'>
"""

from __future__ import annotations

import enum
from dataclasses import dataclass

from kinergy import checks
from kinergy.errors import Code, KinergyError
from kinergy.friction.model import FrictionModel
from kinergy.friction.registry import MODELS

__all__ = [
    "AUTO",
    "FILTER_CUTOFF",
    "MAX_RIDGE",
    "CurrentOptions",
    "FrictionOption",
    "FrictionSearch",
    "Hold",
    "IdentifyOptions",
    "MakkarMethod",
    "Method",
    "NursingOptions",
    "Solver",
    "Target",
    "friction_option",
]


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


class FrictionSearch(enum.StrEnum):
    """``--friction auto``: per joint, the family with the lowest cross-validated current RMS
    (the sequential method's current fit, UR5e eq 18; the full method's too)."""

    AUTO = "auto"


AUTO = FrictionSearch.AUTO
#: the largest ridge weight taken
MAX_RIDGE = 1e12

#: what ``--friction`` resolves to: one family for every joint, the search among families, or
#: None (each joint keeps its own family)
FrictionOption = FrictionModel | FrictionSearch | None


def friction_option(value: FrictionModel | str | None, what: str = "--friction") -> FrictionOption:
    """``--friction``'s text (a family's name or ``auto``) resolved, once, into its type.

    Raises
    ------
    KinergyError
        ``--friction: must be one of ..., auto, got 'dahl'`` (code ``UNKNOWN_CHOICE``).
    """
    if value is None or isinstance(value, FrictionModel | FrictionSearch):
        return value
    if value == AUTO.value:
        return AUTO
    if isinstance(value, str) and value in MODELS:
        return MODELS[value]
    known = ", ".join([*sorted(MODELS), AUTO.value])
    raise KinergyError(f"{what}: must be one of {known}, got {value!r}", Code.UNKNOWN_CHOICE)


@dataclass(frozen=True)
class CurrentOptions:
    """What the torque constants and friction are fitted with on the currents (UR5e eqs 17-18).

    Attributes
    ----------
    friction : FrictionOption
        One family for every joint, :data:`AUTO` (per joint, the family with the lowest
        cross-validated current RMS) or None (each joint's own family); given by name, it is
        resolved here (:func:`friction_option`).
    hold : Hold
    errors : bool
        Whether the fitted parameters' errors are found (the delete-one-block jackknife of
        :mod:`kinergy.identification.uncertainty`); False: the model carries none.
    """

    friction: FrictionOption = None
    hold: Hold = Hold.SEARCH
    errors: bool = True

    def __post_init__(self) -> None:
        object.__setattr__(self, "friction", friction_option(self.friction))

    @property
    def auto(self) -> bool:
        """Whether each joint's family is chosen by cross-validation."""
        return self.friction is AUTO

    @property
    def family(self) -> FrictionModel | None:
        """The one family every joint is fitted with, or None."""
        return self.friction if isinstance(self.friction, FrictionModel) else None


@dataclass(frozen=True)
class IdentifyOptions:
    """The options of an identification.

    Attributes
    ----------
    method : Method
    friction : FrictionOption
        One family (:data:`kinergy.friction.registry.MODELS`) for every joint, :data:`AUTO`, or
        None: each joint's own family; given by name, it is resolved here
        (:func:`friction_option`). The nursing method takes none (it fits Makkar's friction,
        nursing eq 13).
    target : Target
        Full method only.
    solver : Solver
        Full method only.
    ridge : float
        The ridge weight (``solver`` ridge), from 0 to :data:`MAX_RIDGE`.
    errors : bool
        Sequential method: whether the model carries its parameters' errors (the robot file's
        ``[uncertainty]``, :mod:`kinergy.identification.uncertainty`); False skips them (what
        they cost: ``benchmarks/bench_uncertainty.py cost``). Not recorded in the model file.
    """

    method: Method = Method.SEQUENTIAL
    friction: FrictionOption = None
    target: Target = Target.AUTO
    solver: Solver = Solver.OLS
    ridge: float = 0.0
    errors: bool = True

    def record(self) -> dict[str, str | float]:
        """The options as a model file records them (``friction`` only when given)."""
        out: dict[str, str | float] = {"method": self.method.value}
        if self.friction is not None:
            out["friction"] = str(self.friction)
        out.update(target=self.target.value, solver=self.solver.value, ridge=self.ridge)
        return out

    def __post_init__(self) -> None:
        object.__setattr__(self, "method", checks.choice(self.method, Method, "--method"))
        object.__setattr__(self, "target", checks.choice(self.target, Target, "--target"))
        object.__setattr__(self, "solver", checks.choice(self.solver, Solver, "--solver"))
        object.__setattr__(self, "friction", friction_option(self.friction))
        if self.method == Method.NURSING and self.friction is not None:
            raise KinergyError(
                f"--friction {self.friction}: the nursing method fits Makkar's friction (nursing "
                "eq 13) to its friction runs; --friction is taken by the sequential and full "
                "methods",
                Code.UNSUPPORTED,
            )
        ridge = checks.number(self.ridge, "--ridge", ge=0.0, le=MAX_RIDGE)
        object.__setattr__(self, "ridge", ridge)
        if self.method != Method.FULL:
            return
        if self.solver == Solver.RIDGE and ridge == 0.0:
            raise KinergyError(
                "solver 'ridge' needs ridge > 0 (the weight of the prior, e.g. 1e-4)"
            )
        if self.solver != Solver.RIDGE and ridge != 0.0:
            raise KinergyError(
                f"ridge = {ridge:g} is only used by solver 'ridge', not {self.solver.value!r}"
            )


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
