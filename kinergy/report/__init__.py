"""Reports of a model and of a motion's energy: figures (:mod:`kinergy.report.plots`).

Needs matplotlib (``pip install matplotlib``); importing :mod:`kinergy` itself does not.
The public names are those of :mod:`~kinergy.report.plots`, re-exported by its ``__all__``.
"""

from kinergy.report import plots
from kinergy.report.plots import *  # noqa: F403 (re-export: plots.__all__)

__all__ = [*plots.__all__]
