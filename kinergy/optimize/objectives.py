"""What the optimiser minimises: an objective over the drive state of sampled programs.

An objective is any callable ``objective(samples) -> (value, parts)`` that maps the drive model
over B sampled programs (:class:`kinergy.optimize.samples.ProgramSamples`: the
:class:`kinergy.predict.DriveState` at every sample, integration weights, which move each sample
belongs to) to one value per program, shape (B,), and its per-move parts, shape (B, K), that add
up to it. The same objective scores the optimiser's quadrature nodes and the 500 Hz
re-simulation that verifies every result (:mod:`kinergy.optimize.verify`), so a new objective is
one new function or class here, passed as ``objective=`` to
:func:`kinergy.optimize.programs.optimize_program`; the solver does not change. It should be
smooth in the timing (an integral over the samples, not a maximum) and of order one to a few
thousand in its unit (the solver scales it by its value at the start).

:class:`SupplyEnergy` (the optimiser's one objective) is the energy the arm draws from its
supply, as the model predicts it: the joints' electrical powers (UR5e eq 23) summed on the DC
bus, a braking surplus lost in the shunt (the bus power clipped at 0), plus the arm's standing
draw times the cycle time: the drives' DC-bus model (:func:`kinergy.drives.bus.supply_power`,
what ``kinergy energy`` reports as drawn from the supply). Its parts without the standing draw
are the motors' energy (:meth:`SupplyEnergy.motors`).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Protocol

from kinergy.arrays import Array
from kinergy.drives.bus import supply_power
from kinergy.optimize.samples import ProgramSamples

__all__ = ["Objective", "SupplyEnergy"]


class Objective(Protocol):
    """``objective(samples) -> (value (B,), parts (B, K))``: see the module docstring."""

    def __call__(self, samples: ProgramSamples) -> tuple[Array, Array]: ...


@dataclass(frozen=True)
class SupplyEnergy:
    """The energy the arm draws from its supply per program, J: ``int (max(sum_j W_elec,j, 0)
    + P_standby) dt`` (UR5e eq 23 summed on the DC bus, braking surplus lost, standing draw).

    Parameters
    ----------
    standby : float
        Power the arm draws whatever the motion (electronics, brakes released), W (>= 0): adds
        ``standby * cycle time``.
    """

    standby: float = 0.0

    def __call__(self, samples: ProgramSamples) -> tuple[Array, Array]:
        bus = supply_power(samples.drive.power, self.standby)
        return samples.integrate(bus.motors + bus.standby)

    def motors(self, samples: ProgramSamples) -> tuple[Array, Array]:
        """The motors' part alone: the bus energy, braking surplus lost, J ((B,) and (B, K))."""
        return samples.integrate(supply_power(samples.drive.power).motors)
