"""The values the nursing doc publishes for its robot, as data (nursing sections 4.1-4.2, 5).

kinergy compares its own runs with these (``kinergy nursing``) and runs the doc's excitation from
them (:func:`kinergy.experiments.nursing_excitation.table6_motion`). Nothing here is computed.
"""

from __future__ import annotations

import numpy as np

__all__ = [
    "BASE_FREQUENCY",
    "DOC_EQ21",
    "DOC_FRICTION_R2",
    "DOC_TABLE4",
    "DOC_TABLE6",
    "DOC_TABLE8",
]

#: Eq 21's constants for the doc's robot: total reduction n, efficiency eta, K_m (N m/A)
DOC_EQ21 = {"n": 3060.0, "eta": 0.82, "km": 0.0293}
#: Table 4, joint side (N m, rad/s): gamma1..gamma6 of the rotation and the pitch motion
DOC_TABLE4 = {
    "rotation": (32.36, 9.94, 5.25, 30.54, 10.77, 2.68),
    "pitch": (39.1, 8.65, 6.54, 10.04, 19.71, 3.05),
}
#: R^2 of the doc's friction fits (section 4.1, conclusion 2)
DOC_FRICTION_R2 = {"rotation": 0.931, "pitch": 0.927}
#: Table 8: RMSE between measured and predicted joint torques, N m (printed "N m^2"), joints 1-6
DOC_TABLE8 = (14.372, 11.982, 6.934, 5.557, 3.932, 3.152)
#: Table 6: excitation coefficients a_l, b_l (rows joints 1-6, columns l = 1..3, rad/s) and q0 (rad)
DOC_TABLE6 = {
    "a": (
        (0.204, -0.004, -0.201),
        (0.163, -0.106, -0.056),
        (-0.106, 0.038, 0.067),
        (0.058, -0.007, -0.050),
        (-0.071, 0.051, 0.019),
        (0.031, -0.021, 0.019),
    ),
    "b": (
        (0.139, -0.440, 0.247),
        (0.208, 0.074, -0.119),
        (-0.255, -0.055, 0.122),
        (0.038, -0.225, 0.137),
        (-0.325, 0.017, 0.097),
        (-0.086, -0.196, 0.159),
    ),
    "q0": (0.002, 0.328, -0.386, -0.045, -0.453, -0.208),
}
#: eq 22's base frequency, rad/s (a 10 s period)
BASE_FREQUENCY = 0.2 * np.pi
