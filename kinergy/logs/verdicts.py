"""The named plausibility checks of a log and what they conclude: the checks ``--accept`` takes
(:class:`Check`), the findings while they run (:class:`Findings`) and the verdict on one log
(:class:`LogChecks`). The checks themselves: :mod:`kinergy.logs.signal_checks` (time, units,
speeds, ratings, constant) and :mod:`kinergy.logs.robot_check` (robot), folded over a log's
chunks by :class:`kinergy.logs.checks.LogCheck`.
"""

from __future__ import annotations

import enum
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field

from kinergy.errors import KinergyError
from kinergy.model.robot import Robot

__all__ = ["CHECKS", "Check", "Findings", "LogChecks", "first", "joint_label", "parse_accept"]


class Check(enum.StrEnum):
    """The named checks ``--accept`` takes."""

    TIME = "time"
    UNITS = "units"
    SPEEDS = "speeds"
    RATINGS = "ratings"
    CONSTANT = "constant"
    ROBOT = "robot"
    FIT = "fit"


#: what each check verifies, for help texts and the documentation
CHECKS: dict[Check, str] = {
    Check.TIME: "a plausible sample period (0.5 ms to 0.1 s)",
    Check.UNITS: "positions within the joint limits (rad, not degrees), speeds and temperatures "
    "plausible",
    Check.SPEEDS: "each joint's logged speed equals the derivative of its logged position",
    Check.RATINGS: "currents, torques and voltages within 5 times the robot's ratings",
    Check.CONSTANT: "no measured signal stuck at one value while its joint moves",
    Check.ROBOT: "the robot model's torques and currents match the logged ones (ratio and sign "
    "per joint)",
    Check.FIT: "identify: the fit explains the identification logs (R² >= 0 for every joint that "
    "moved)",
}


def parse_accept(values: Iterable[str]) -> frozenset[Check]:
    """``--accept`` values (names or comma-separated lists) as checks.

    Raises
    ------
    KinergyError
        A name that is not a check, with the known ones.
    """
    out: set[Check] = set()
    for value in values:
        for name in value.split(","):
            name = name.strip().lower()
            if name == "all":
                out.update(Check)
                continue
            try:
                out.add(Check(name))
            except ValueError:
                known = ", ".join(c.value for c in Check)
                raise KinergyError(
                    f"--accept: unknown check {name!r}; the checks are {known} (or all)"
                ) from None
    return frozenset(out)


@dataclass(frozen=True)
class LogChecks:
    """What the checks found in one log.

    Attributes
    ----------
    log : str
    passed : tuple of str
        Checks that ran and passed.
    accepted : tuple of str
        Checks that failed and were accepted by the user (``--accept``), with what they saw.
    not_checked : tuple of str
        Checks the log gave nothing to run on, with why.
    warnings : tuple of str
        What passed but may still make a result wrong.
    notes : tuple of str
        What the checks could not judge in part (joints in the noise), routine.
    """

    log: str
    passed: tuple[str, ...] = ()
    accepted: tuple[str, ...] = ()
    not_checked: tuple[str, ...] = ()
    warnings: tuple[str, ...] = ()
    notes: tuple[str, ...] = ()


@dataclass
class Findings:
    """What the checks concluded, per check: failures (which stop), passes, warnings."""

    failed: dict[Check, list[str]] = field(default_factory=dict)
    passed: list[Check] = field(default_factory=list)
    skipped: dict[Check, str] = field(default_factory=dict)
    warnings: list[str] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)

    def fail(self, check: Check, text: str) -> None:
        self.failed.setdefault(check, []).append(text)

    def verdict(self, check: Check, ran: bool, why_not: str = "") -> None:
        if check in self.failed:
            return
        if ran:
            self.passed.append(check)
        else:
            self.skipped[check] = why_not


def first(texts: Sequence[str], count: int = 3) -> str:
    """The first ``count`` of ``texts`` joined, and how many more there are."""
    more = len(texts) - count
    return "; ".join(texts[:count]) + (f"; and {more} more" if more > 0 else "")


def joint_label(robot: Robot, j: int) -> str:
    """``joint 2 (shoulder_lift)``: joint ``j`` (from 0) as messages name it."""
    return f"joint {j + 1} ({robot.joints[j].name})"
