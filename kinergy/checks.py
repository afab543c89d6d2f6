"""Checks of what a user gives, where it enters: each returns the parsed, typed value or raises one
:class:`~kinergy.errors.KinergyError` line.

In the manner of pytransform3d's ``check_matrix``: a check does not validate by side effect and
pass the raw value on; it returns the value the code below works with (a ``float``, a read-only
float64 array, the mapping, the enum member), so that inner code trusts its inputs.

Every message has one style, ``WHAT: must be RULE, got VALUE``::

    >>> number(-1, "--ridge", ge=0.0)
    Traceback (most recent call last):
    ...
    kinergy.errors.KinergyError: --ridge: must be a finite number >= 0, got -1
    >>> vector([1, 2], "gravity", length=3)
    Traceback (most recent call last):
    ...
    kinergy.errors.KinergyError: gravity: must be 3 finite numbers, got [1, 2]

``WHAT`` names what the user wrote: a flag (``--ridge``), a field (``joints[2] (elbow).mass``),
a keyword argument. Each error carries a :class:`~kinergy.errors.Code` (``NUMBER``, ``SHAPE``,
``UNKNOWN_KEY``, ``UNKNOWN_CHOICE``) for callers that must tell them apart.
"""

from __future__ import annotations

import enum
import math
import re
from collections.abc import Collection, Mapping
from typing import Any, TypeVar

import numpy as np

from kinergy.arrays import Array
from kinergy.errors import Code, KinergyError

__all__ = ["choice", "flag", "integer", "known_keys", "number", "plain_text", "vector"]

E = TypeVar("E", bound=enum.Enum)


def flag(name: str) -> str:
    """The command-line flag of an option called ``name`` in Python, as messages name it
    (``tool_symmetry`` -> ``--tool-symmetry``)."""
    return "--" + name.replace("_", "-")


def _shown(value: Any) -> str:
    """``value`` as a message shows it: numbers as ``g``, arrays as lists, text quoted."""
    if isinstance(value, bool) or value is None or isinstance(value, str):
        return repr(value)
    if isinstance(value, int | float | np.integer | np.floating):
        return f"{float(value):g}" if not isinstance(value, int | np.integer) else str(value)
    if isinstance(value, np.ndarray):
        return str(value.tolist())
    text = repr(value)
    return text if len(text) <= 80 else text[:77] + "..."


def _rule(
    gt: float | None, ge: float | None, lt: float | None, le: float | None, size: float | None
) -> str:
    """The bounds in words: ``> 0``, ``>= 0 and <= 1``, ``of size at most 100``."""
    parts = [
        f"{sign} {bound:g}"
        for sign, bound in ((">", gt), (">=", ge), ("<", lt), ("<=", le))
        if bound is not None
    ]
    if size is not None:
        parts.append(f"of size at most {size:g}")
    return " and ".join(parts)


def _within(
    x: Array | float,
    gt: float | None,
    ge: float | None,
    lt: float | None,
    le: float | None,
    size: float | None,
) -> bool:
    arr = np.asarray(x)
    return bool(
        (gt is None or np.all(arr > gt))
        and (ge is None or np.all(arr >= ge))
        and (lt is None or np.all(arr < lt))
        and (le is None or np.all(arr <= le))
        and (size is None or np.all(np.abs(arr) <= size))
    )


def number(
    value: Any,
    what: str,
    *,
    gt: float | None = None,
    ge: float | None = None,
    lt: float | None = None,
    le: float | None = None,
    size: float | None = None,
) -> float:
    """``value`` as a finite float within the bounds given.

    Parameters
    ----------
    value : int or float
        A number (``bool`` and text are refused: ``"1"`` in a TOML file is a slip).
    what : str
        What the user wrote it as, for the message.
    gt, ge, lt, le : float, optional
        ``value > gt``, ``>= ge``, ``< lt``, ``<= le``.
    size : float, optional
        ``|value| <= size``.

    Returns
    -------
    float

    Raises
    ------
    KinergyError
        ``WHAT: must be a finite number > 0, got -1`` (code ``NUMBER``).
    """
    rule = _rule(gt, ge, lt, le, size)
    ok = not isinstance(value, bool) and isinstance(value, int | float | np.integer | np.floating)
    x = float(value) if ok else math.nan
    if not (math.isfinite(x) and _within(x, gt, ge, lt, le, size)):
        wanted = f"a finite number {rule}".rstrip()
        raise KinergyError(f"{what}: must be {wanted}, got {_shown(value)}", Code.NUMBER)
    return x


def integer(value: Any, what: str, *, ge: int | None = None, le: int | None = None) -> int:
    """``value`` as an int within ``[ge, le]`` (a float only when whole: ``2.0``; a count, a
    seed).

    Raises
    ------
    KinergyError
        ``WHAT: must be a whole number >= 1 and <= 50, got 0`` (code ``NUMBER``).
    """
    ok = not isinstance(value, bool) and isinstance(value, int | float | np.integer | np.floating)
    whole = ok and math.isfinite(float(value)) and float(value) == int(value)
    n = int(value) if whole else None
    if n is None or (ge is not None and n < ge) or (le is not None and n > le):
        rule = " and ".join(f"{s} {b}" for s, b in ((">=", ge), ("<=", le)) if b is not None)
        wanted = f"a whole number {rule}".rstrip()
        raise KinergyError(f"{what}: must be {wanted}, got {_shown(value)}", Code.NUMBER)
    return n


def vector(
    value: Any,
    what: str,
    *,
    length: int | None = None,
    gt: float | None = None,
    ge: float | None = None,
    lt: float | None = None,
    le: float | None = None,
    size: float | None = None,
) -> Array:
    """``value`` as a read-only float64 array of finite numbers, shape ``(length,)``.

    Parameters
    ----------
    value : array_like
        Numbers (a sequence, an array).
    what : str
        What the user wrote it as.
    length : int, optional
        The count wanted (default: any count, one dimension).
    gt, ge, lt, le, size : float, optional
        Bounds every element keeps (:func:`number`).

    Returns
    -------
    ndarray, shape (length,)
        float64, not writeable.

    Raises
    ------
    KinergyError
        ``WHAT: must be 3 finite numbers, got [1, 2]`` (code ``SHAPE`` for the count, ``NUMBER``
        for a value).
    """
    wanted = ("" if length is None else f"{length} ") + "finite numbers"
    try:
        arr = np.array(value, dtype=float)
    except (TypeError, ValueError):
        raise KinergyError(f"{what}: must be {wanted}, got {_shown(value)}", Code.SHAPE) from None
    if arr.ndim != 1 or (length is not None and arr.shape != (length,)):
        shown = _shown(value) if arr.ndim <= 1 else f"shape {arr.shape}"
        raise KinergyError(f"{what}: must be {wanted}, got {shown}", Code.SHAPE)
    if not (np.all(np.isfinite(arr)) and _within(arr, gt, ge, lt, le, size)):
        rule = _rule(gt, ge, lt, le, size)
        wanted += f", each {rule}" if rule else ""
        raise KinergyError(f"{what}: must be {wanted}, got {_shown(arr)}", Code.NUMBER)
    arr.setflags(write=False)
    return arr


def known_keys(data: Any, allowed: Collection[str], what: str) -> Mapping[str, Any]:
    """``data`` as a mapping whose keys are all ``allowed``.

    Raises
    ------
    KinergyError
        ``WHAT: must be a table, got list``; ``WHAT: unknown field(s) 'x' (allowed: a, b)``
        (code ``UNKNOWN_KEY``).
    """
    if not isinstance(data, Mapping):
        raise KinergyError(f"{what}: must be a table, got {type(data).__name__}", Code.SHAPE)
    unknown = sorted(str(k) for k in set(data) - set(allowed))
    if unknown:
        raise KinergyError(
            f"{what}: unknown field(s) {', '.join(repr(u) for u in unknown)} "
            f"(allowed: {', '.join(sorted(allowed))})",
            Code.UNKNOWN_KEY,
        )
    return data


def choice(value: Any, kind: type[E], what: str) -> E:
    """``value`` as a member of the enum ``kind``: a member as it is, else the member whose value
    it is (``"full"`` -> ``Method.FULL``).

    Raises
    ------
    KinergyError
        ``WHAT: must be one of sequential, full, nursing, got 'ful'`` (code
        ``UNKNOWN_CHOICE``).
    """
    if isinstance(value, kind):
        return value
    for member in kind:
        if member.value == value and not isinstance(value, bool):
            return member
    known = ", ".join(str(m.value) for m in kind)
    raise KinergyError(f"{what}: must be one of {known}, got {_shown(value)}", Code.UNKNOWN_CHOICE)


#: control characters text printed to a terminal may not hold (a terminal acts on them: colours,
#: bells, a cursor sent elsewhere), and the same but line breaks and tabs
_CONTROL = re.compile(r"[\x00-\x1f\x7f-\x9f]")
_CONTROL_BUT_BREAKS = re.compile(r"[\x00-\x08\x0b-\x1f\x7f-\x9f]")


def plain_text(value: str, what: str, *, breaks: bool = False) -> str:
    """``value`` (a name that results print) without control characters; with ``breaks``, line
    breaks and tabs are allowed (a description).

    Raises
    ------
    KinergyError
        ``robot name: must be plain text (no control characters: \\x07, \\x1b), got
        'ur5e\\x1b[31mRED\\x07'``, the value escaped.
    """
    found = sorted(set((_CONTROL_BUT_BREAKS if breaks else _CONTROL).findall(value)))
    if found:
        shown = ", ".join(repr(c)[1:-1] for c in found)
        escaped = value.encode("unicode_escape").decode("ascii")
        raise KinergyError(
            f"{what}: must be plain text (no control characters: {shown}; results print it to the "
            f"terminal), got '{escaped}'"
        )
    return value
