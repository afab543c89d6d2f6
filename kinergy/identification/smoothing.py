"""The friction's smoothing speed against measured joint torques (the full method).

The full method fits the friction's linear levels, not its shape (:mod:`kinergy.identification.full`);
a Coulomb term ``coulomb * tanh(wm / smoothing)`` whose smoothing is far from the arm's misses the
torque at every reversal. A robot file often has no measured shape (a URDF's ``<dynamics>`` gives
levels only, and a joint without friction is fitted with the default smoothing); Gaz et al.'s
Panda, fitted to its link-side torque sensors, has 0.12-0.39 rad/s on the joint side.

Against measured torques the regression is therefore also made with a common joint-side smoothing
``s`` from :data:`GRID` (motor side ``s * |N_mm|``) for every joint whose family has a
``smoothing`` and no load dependence, and the fit with the least squared residual over all joints
and samples is kept, the model's own smoothings among the candidates (one pass over the logs
each; one parameter chosen from a few candidates on many thousands of samples).
"""

from __future__ import annotations

import dataclasses

import numpy as np

from kinergy.errors import KinergyError
from kinergy.identification.chunks import LogChunks
from kinergy.identification.columns import Regression
from kinergy.identification.regression import FlowFit, fit_power_flow

__all__ = ["GRID", "Smoothing", "search_smoothing"]

#: joint-side smoothing speeds tried, rad/s
GRID = (0.003, 0.01, 0.03, 0.1, 0.3)


@dataclasses.dataclass(frozen=True)
class Smoothing:
    """What the search chose: the joint-side smoothing (rad/s; None: the model's own) and the
    motors it was tried on (0-based)."""

    chosen: float | None
    motors: tuple[int, ...]

    def note(self) -> str | None:
        if self.chosen is None or not self.motors:
            return None
        joints = ", ".join(str(m + 1) for m in self.motors)
        return (
            f"friction smoothing of joint(s) {joints}: {self.chosen:g} rad/s (joint side), the "
            f"least squared torque residual of {', '.join(f'{s:g}' for s in GRID)} rad/s and "
            "the model's own"
        )


def search_smoothing(
    reg: Regression, logs: LogChunks, expressions: list[str]
) -> tuple[Regression, FlowFit, Smoothing]:
    """The regression (module docstring) with the smoothing whose fit leaves the least squared
    residual, its fit and what was chosen; ``reg`` and its fit when no motor takes a smoothing."""
    fit = fit_power_flow(reg, logs, expressions)
    motors = tuple(
        m
        for m, model in enumerate(reg.models)
        if "smoothing" in model.parameters and not model.needs_load and len(model.linear)
    )
    if not motors:
        return reg, fit, Smoothing(None, ())
    gear = np.max(np.abs(reg.n_mat), axis=1)
    best, chosen = (reg, fit), None
    for s in GRID:
        params = [dict(p) for p in reg.params]
        for m in motors:
            params[m]["smoothing"] = s * float(gear[m])
        trial = dataclasses.replace(reg, params=params)
        try:
            tried = fit_power_flow(trial, logs, expressions)
        except KinergyError:  # a smoothing that leaves the columns singular is no candidate
            continue
        if tried.ols.solution.sse < best[1].ols.solution.sse:
            best, chosen = (trial, tried), s
    return best[0], best[1], Smoothing(chosen, motors)
