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

__all__ = ["AUTO", "IdentifyOptions", "Method", "Solver", "Target"]

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

    def __post_init__(self) -> None:
        if self.friction is not None and self.friction != AUTO and self.friction not in MODELS:
            known = ", ".join([*sorted(MODELS), AUTO])
            raise KinergyError(f"--friction: unknown model {self.friction!r}; known: {known}")
        if not 0.0 <= self.ridge < float("inf"):
            raise KinergyError(f"--ridge must be >= 0 and finite, got {self.ridge}")
