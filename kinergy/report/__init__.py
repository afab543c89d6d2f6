"""Reports of a model and of a motion's energy: figures (:mod:`kinergy.report.plots`).

Needs matplotlib (``pip install matplotlib``); importing :mod:`kinergy` itself does not.
"""

from kinergy.report.plots import (
    energy_breakdown,
    error_boxplot,
    pareto,
    power_energy,
    save,
    time_series,
)

__all__ = [
    "energy_breakdown",
    "error_boxplot",
    "pareto",
    "power_energy",
    "save",
    "time_series",
]
