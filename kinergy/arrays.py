"""The array type every module's signatures use.

``Array`` is a float64 NumPy array of any shape; each docstring says the shape and units.
It is defined here once so that a change of precision or of typing style is one line.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

__all__ = ["Array"]

Array = NDArray[np.float64]
