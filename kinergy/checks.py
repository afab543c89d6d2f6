"""Checks of what a user gives, where it enters: each returns the parsed, typed value or raises one
:class:`~kinergy.errors.KinergyError` line, ``WHAT: must be RULE, got VALUE``.

(The ``number`` and ``choice`` of the input checks, as they are being written beside this
branch; replaced by that module when it lands.)
"""

from __future__ import annotations

import enum
import math
from typing import Any, TypeVar

import numpy as np

from kinergy.errors import KinergyError

__all__ = ["choice", "integer", "number"]

E = TypeVar("E", bound=enum.Enum)


def _shown(value: Any) -> str:
    if isinstance(value, bool) or value is None or isinstance(value, str):
        return repr(value)
    if isinstance(value, int | np.integer):
        return str(value)
    if isinstance(value, float | np.floating):
        return f"{float(value):g}"
    return repr(value)


def number(
    value: Any,
    what: str,
    *,
    gt: float | None = None,
    ge: float | None = None,
    lt: float | None = None,
    le: float | None = None,
) -> float:
    """``value`` as a finite float within the bounds given (``> gt``, ``>= ge``, ``< lt``,
    ``<= le``); else ``WHAT: must be a finite number > 0, got -1``."""
    ok = not isinstance(value, bool) and isinstance(value, int | float | np.integer | np.floating)
    x = float(value) if ok else math.nan
    bounds = ((">", gt), (">=", ge), ("<", lt), ("<=", le))
    within = all(
        b is None or {">": x > b, ">=": x >= b, "<": x < b, "<=": x <= b}[s] for s, b in bounds
    )
    if not (math.isfinite(x) and within):
        rule = " and ".join(f"{s} {b:g}" for s, b in bounds if b is not None)
        wanted = f"a finite number {rule}".rstrip()
        raise KinergyError(f"{what}: must be {wanted}, got {_shown(value)}")
    return x


def integer(value: Any, what: str, *, ge: int | None = None, le: int | None = None) -> int:
    """``value`` as an int within ``[ge, le]`` (a float only when whole: ``2.0``); else
    ``WHAT: must be a whole number >= 1 and <= 50, got 0``."""
    ok = not isinstance(value, bool) and isinstance(value, int | float | np.integer | np.floating)
    whole = ok and math.isfinite(float(value)) and float(value) == int(value)
    n = int(value) if whole else None
    if n is None or (ge is not None and n < ge) or (le is not None and n > le):
        rule = " and ".join(f"{s} {b}" for s, b in ((">=", ge), ("<=", le)) if b is not None)
        wanted = f"a whole number {rule}".rstrip()
        raise KinergyError(f"{what}: must be {wanted}, got {_shown(value)}")
    return n


def choice(value: Any, kind: type[E], what: str) -> E:
    """``value`` as a member of the enum ``kind`` (a member, or the member whose value it is);
    else ``WHAT: must be one of a, b, got 'c'``."""
    if isinstance(value, kind):
        return value
    for member in kind:
        if member.value == value and not isinstance(value, bool):
            return member
    known = ", ".join(str(m.value) for m in kind)
    raise KinergyError(f"{what}: must be one of {known}, got {_shown(value)}")
