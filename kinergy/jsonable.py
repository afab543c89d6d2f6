"""The one JSON serializer: typed results (frozen dataclasses), numpy values and plain data.

Every ``--json`` output and every result's ``to_dict`` goes through :func:`to_jsonable`, so the rules
hold everywhere:

- a dataclass becomes an object of its fields, in declaration order; a field declared with
  ``metadata={"json": False}`` is left out, one with ``metadata={"json": callable}`` is written as
  ``callable(value)`` (say, a robot as its name); one declared with :data:`OPTIONAL` metadata
  is left out while it is None (a figure a method reports only when it has the data);
- numpy scalars and arrays become numbers and (nested) lists; tuples become lists; mappings
  become objects with string keys;
- NaN and infinities become ``null``: JSON has no NaN, and a bare ``NaN`` breaks other tools'
  parsers.
"""

from __future__ import annotations

import dataclasses
import json
import math
from collections.abc import Mapping
from typing import Any

import numpy as np

__all__ = ["OPTIONAL", "dumps", "to_jsonable"]

#: dataclass field metadata: leave the field out of JSON while its value is None
OPTIONAL = {"omit_none": True}


def _number(x: float) -> float | None:
    return x if math.isfinite(x) else None


def to_jsonable(value: Any) -> Any:
    """``value`` as plain JSON data (dict, list, str, int, float, bool, None); see the module
    docstring for the rules.

    Raises
    ------
    TypeError
        A value of a type JSON cannot hold (a programming error, not a user's).
    """
    if value is None or isinstance(value, bool | str):
        return value
    if isinstance(value, int | np.integer) and not isinstance(value, np.bool_):
        return int(value)
    if isinstance(value, float | np.floating):
        return _number(float(value))
    if isinstance(value, np.bool_):
        return bool(value)
    if isinstance(value, np.ndarray):
        return to_jsonable(value.tolist())
    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        out: dict[str, Any] = {}
        for f in dataclasses.fields(value):
            how = f.metadata.get("json", True)
            if how is False:
                continue
            item = getattr(value, f.name)
            if item is None and f.metadata.get("omit_none"):
                continue
            out[f.name] = to_jsonable(how(item) if callable(how) else item)
        return out
    if isinstance(value, Mapping):
        return {str(k): to_jsonable(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [to_jsonable(v) for v in value]
    raise TypeError(f"cannot write a {type(value).__name__} as JSON")


def dumps(value: Any, *, indent: int | None = 2) -> str:
    """``value`` as a JSON text (:func:`to_jsonable`, then strict JSON: never a bare NaN)."""
    return json.dumps(to_jsonable(value), indent=indent, allow_nan=False)
