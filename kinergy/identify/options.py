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

from kinergy.errors import KinergyError
from kinergy.friction.registry import MODELS

__all__ = ["AUTO", "CurrentOptions", "Hold", "IdentifyOptions", "Method", "Solver", "Target"]

#: ``friction``: per joint, the model with the lowest cross-validated current RMS
AUTO = "auto"


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
    tries it (:mod:`kinergy.identify.sequential`): each fraction of
    :data:`~kinergy.identify.drive_steps.HOLDINGS`, keeping whichever explains the currents best
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
    """The options of an identification.

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
        The ridge weight (``solver`` ridge), >= 0.
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
        _check_friction(self.friction)
        if not 0.0 <= self.ridge < float("inf"):
            raise KinergyError(f"--ridge must be >= 0 and finite, got {self.ridge}")
