"""The UR5e doc's result tables, as data, for comparison in reports (UR5e doc Tables V, VII, VIII).

Each accuracy table holds, per test and joint, ``(mean, max, rms, r2)`` of the error; units N m
(Table V, torque against ``target_moment``) and A (Table VII, current against ``actual_current``).
Table VIII holds per joint ``(E_mech, E_elec)`` in J and the overall efficiency.
"""

from __future__ import annotations

__all__ = ["TABLE_V", "TABLE_VII", "TABLE_VIII", "TABLE_VIII_EFFICIENCY", "TABLE_VIII_TOTAL"]

Row = tuple[float, float, float, float]

#: Table V: frictionless (rigid body + rotor inertia) torque model accuracy
TABLE_V: dict[str, list[Row]] = {
    "A": [
        (0.001, 1.453, 0.355, 0.997),
        (0.054, 1.344, 0.369, 0.998),
        (0.011, 0.287, 0.066, 0.999),
        (0.001, 0.077, 0.018, 0.998),
        (-0.001, 0.032, 0.008, 0.999),
        (0.000, 0.009, 0.002, 0.999),
    ],
    "B": [
        (-0.001, 1.430, 0.363, 0.998),
        (-0.140, 1.356, 0.367, 0.998),
        (0.005, 0.565, 0.090, 0.999),
        (0.002, 0.173, 0.037, 0.998),
        (-0.008, 0.061, 0.022, 0.998),
        (-0.000, 0.015, 0.003, 0.999),
    ],
}

#: Table VII: current model accuracy
TABLE_VII: dict[str, list[Row]] = {
    "A": [
        (-0.020, 1.422, 0.188, 0.985),
        (0.000, 1.459, 0.165, 0.997),
        (0.017, 0.882, 0.124, 0.997),
        (-0.007, 0.310, 0.040, 0.995),
        (0.014, 0.287, 0.037, 0.995),
        (-0.011, 0.381, 0.050, 0.995),
    ],
    "B": [
        (-0.007, 1.324, 0.169, 0.989),
        (-0.022, 1.346, 0.182, 0.996),
        (0.016, 0.833, 0.119, 0.997),
        (-0.009, 0.256, 0.038, 0.996),
        (-0.007, 0.309, 0.037, 0.993),
        (-0.037, 0.358, 0.066, 0.991),
    ],
}

#: Table VIII: estimated mechanical and electrical energy per joint, J
TABLE_VIII: dict[str, list[tuple[float, float]]] = {
    "A": [(220.6, 251.6), (49.36, 72.0), (228.7, 264.2), (44.2, 55.5), (71.1, 83.7), (97.3, 117.2)],
    "B": [(232.6, 265.5), (52.6, 73.3), (186.8, 216.8), (56.6, 70.5), (54.3, 64.1), (92.7, 111.7)],
}
#: Table VIII: its "overall" row, (E_mech, E_elec) in J as printed (not the sum of its rounded
#: joint rows: 844.2 J for test A)
TABLE_VIII_TOTAL = {"A": (711.3, 845.1), "B": (675.6, 805.9)}
#: Table VIII: overall efficiency eta = E_mech / E_elec
TABLE_VIII_EFFICIENCY = {"A": 0.8417, "B": 0.8383}
