"""JSON is always valid (null, never NaN) and progress is silent off a terminal (issue 15)."""

from __future__ import annotations

import json
import math
from dataclasses import dataclass, field

import click
import numpy as np
from click.testing import CliRunner

from kinergy.cli.common import progress
from kinergy.jsonable import OPTIONAL, dumps


@dataclass(frozen=True)
class _Result:
    value: float
    values: np.ndarray
    missing: float | None = field(default=None, metadata=OPTIONAL)


def _strict(text: str) -> object:
    def refuse(name: str) -> object:
        raise AssertionError(f"bare {name} in JSON")

    return json.loads(text, parse_constant=refuse)


def test_non_finite_numbers_are_null() -> None:
    result = _Result(math.nan, np.array([1.0, np.inf, -np.inf, np.float32("nan")]))
    data = _strict(dumps({"r": result, "x": np.float64("nan"), "t": (math.inf,)}))
    assert data == {"r": {"value": None, "values": [1.0, None, None, None]}, "x": None, "t": [None]}


def test_progress_is_silent_when_stderr_is_not_a_terminal() -> None:
    @click.command()
    def slow() -> None:
        with progress() as say:
            say("step one")
            say("step two")
        click.echo("done")

    result = CliRunner().invoke(slow, [])
    assert result.exit_code == 0 and result.stdout == "done\n" and result.stderr == ""
