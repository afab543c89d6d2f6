"""What the timing optimiser minimises: objectives over the drive state of sampled programs.

An objective is any callable ``objective(samples) -> (value, parts)`` that maps the drive model
over B sampled programs (:class:`kinergy.optimize.program.ProgramSamples`: the
:class:`kinergy.predict.DriveState` at every sample, integration weights, which move each sample
belongs to) to one value per program, shape (B,), and its per-move parts, shape (B, K), that add
up to it. The same objective scores the optimiser's quadrature nodes and the 500 Hz
re-simulation that verifies every result (:mod:`kinergy.optimize.verify`), so a new objective is
one new function or class here, passed as ``objective=`` to
:func:`kinergy.optimize.timing_problem` or :func:`kinergy.optimize.optimize_timing`; the solver
does not change. It should be smooth in the timing (an integral over the samples, not a maximum)
and of order one to a few thousand in its unit (the solver scales it by its value at the start).

:class:`ElectricalEnergy` (the default) is the motors' electrical energy (UR5e eqs 23, 26) summed
on the DC bus: ``int sum_j W_elec,j dt`` with ``W_elec = tau_m^2 / k_m^2 + (k_b/k_t) wm tau_m``
(:func:`kinergy.predict.drive_state`), braking energy returned to the bus (signed, as the seed)
or, without recovery, the summed bus power clipped at 0 (the supply takes nothing back), as
:func:`kinergy.accounting.energy.energy` counts the total.

:class:`SupplyEnergy` (what :func:`kinergy.optimize.programs.optimize_program` minimises) is the
energy the arm draws from its supply: the joints' electrical powers summed on the DC bus, a
braking surplus lost in the shunt (the bus power clipped at 0), plus the controller's standby
power times the cycle time: the drives' DC-bus model (:func:`kinergy.drives.bus.supply_power`,
what ``kinergy energy`` reports as drawn from the supply). :data:`PROGRAM_OBJECTIVE` names the
objective the program optimiser uses: switching is that one line.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Protocol

import numpy as np

from kinergy.arrays import Array
from kinergy.drives.bus import supply_power
from kinergy.optimize.program import ProgramSamples

__all__ = ["PROGRAM_OBJECTIVE", "ElectricalEnergy", "Objective", "SupplyEnergy", "bus_power"]


class Objective(Protocol):
    """``objective(samples) -> (value (B,), parts (B, K))``: see the module docstring."""

    def __call__(self, samples: ProgramSamples) -> tuple[Array, Array]: ...


def bus_power(samples: ProgramSamples, *, recovery: bool = True) -> Array:
    """Electrical power of all motors on the DC bus at every sample, W, shape (B * M,)
    (UR5e eq 23 summed over the joints; clipped at 0 without ``recovery``)."""
    bus = samples.drive.power.sum(axis=1)
    return bus if recovery else np.maximum(bus, 0.0)


@dataclass(frozen=True)
class ElectricalEnergy:
    """The motors' electrical energy per program, J (UR5e eq 26 summed over the joints).

    Parameters
    ----------
    recovery : bool
        Braking energy returns to the bus (default, as the seed); otherwise the summed bus power
        is clipped at 0.
    """

    recovery: bool = True

    def __call__(self, samples: ProgramSamples) -> tuple[Array, Array]:
        return samples.integrate(bus_power(samples, recovery=self.recovery))


@dataclass(frozen=True)
class SupplyEnergy:
    """The energy the arm draws from its supply per program, J: ``int (max(sum_j W_elec,j, 0)
    + P_standby) dt`` (UR5e eq 23 summed on the DC bus, braking surplus lost, standby power).

    Parameters
    ----------
    standby : float
        Power the controller and the arm draw whatever the motion, W (>= 0): adds
        ``standby * cycle time``.
    """

    standby: float = 0.0

    def __call__(self, samples: ProgramSamples) -> tuple[Array, Array]:
        bus = supply_power(samples.drive.power, self.standby)
        return samples.integrate(bus.motors + bus.standby)


#: the objective of :func:`kinergy.optimize.programs.optimize_program`, given the standby power
PROGRAM_OBJECTIVE = SupplyEnergy
