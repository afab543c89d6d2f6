"""Fuzzing ``kinergy robot import-urdf`` and ``robot export`` (issue 27): an exported URDF with one
attribute value or element text replaced by a hostile token, or cut short; a robot file with one
number replaced by an extreme one, exported to both formats.

Every example goes through :func:`clicase.run_case`: no traceback, a refusal is one line on
stderr, no file changed but the declared outputs, under 10 s. A file that is accepted must give a
robot that exports again to both formats.
"""

from __future__ import annotations

import copy
import re
import shutil
import tempfile
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
import tomli_w
from clicase import run_case
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from kinergy.model import load_robot, robot_to_dict
from kinergy.model.urdf_export import robot_to_urdf

FUZZ = settings(
    derandomize=True,
    deadline=None,
    max_examples=40,
    suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow],
    database=None,
)

TOKENS = ["0", "-1", "1e308", "-1e308", "nan", "inf", "x", "", "1 2", "0 0 0", "1e-320", "3.0"]
#: attribute values and element texts of the exported file: (start, end) of each
_VALUES = re.compile(r'="([^"]*)"|>([^<>\s][^<>]*)</')

_FOLDERS: list[Path] = []


@pytest.fixture(autouse=True, scope="module")
def _clean_up() -> Iterator[None]:
    yield
    for folder in _FOLDERS:
        shutil.rmtree(folder, ignore_errors=True)


def _urdf(robot: str) -> str:
    return robot_to_urdf(load_robot(robot)).text


TEXTS = {name: _urdf(name) for name in ("ur5e", "nursing-arm")}
SPANS = {
    name: [m.span(1) if m.group(1) is not None else m.span(2) for m in _VALUES.finditer(text)]
    for name, text in TEXTS.items()
}


def _check(text: str) -> None:
    _FOLDERS.append(Path(tempfile.mkdtemp(prefix="kinergy-fuzz-export-")))
    folder = _FOLDERS[-1]
    (folder / "robot.urdf").write_text(text, encoding="utf-8")
    outcome = run_case(
        ["robot", "import-urdf", "robot.urdf", "--out", "m.toml"], folder, outputs=["m.toml"]
    )
    if outcome.status == 0:
        for fmt in ("urdf", "mjcf"):
            run_case(
                ["robot", "export", "m.toml", "--format", fmt, "--out", f"again.{fmt}"],
                folder,
                outputs=[f"again.{fmt}"],
                refuse=False,
            )


@FUZZ
@given(
    robot=st.sampled_from(sorted(TEXTS)),
    index=st.integers(min_value=0, max_value=10**6),
    token=st.sampled_from(TOKENS),
)
def test_one_value_replaced(robot: str, index: int, token: str) -> None:
    start, end = SPANS[robot][index % len(SPANS[robot])]
    text = TEXTS[robot]
    _check(text[:start] + token + text[end:])


@FUZZ
@given(robot=st.sampled_from(sorted(TEXTS)), fraction=st.floats(min_value=0.0, max_value=1.0))
def test_cut_short(robot: str, fraction: float) -> None:
    text = TEXTS[robot]
    _check(text[: int(fraction * len(text))])


def _numbers(data: Any, path: tuple[Any, ...] = ()) -> Iterator[tuple[Any, ...]]:
    """Paths to every number of a robot dict."""
    if isinstance(data, dict):
        for key, value in data.items():
            yield from _numbers(value, (*path, key))
    elif isinstance(data, list):
        for k, value in enumerate(data):
            yield from _numbers(value, (*path, k))
    elif isinstance(data, int | float) and not isinstance(data, bool):
        yield path


ROBOTS = {name: robot_to_dict(load_robot(name)) for name in ("ur10e", "nursing-arm", "panda")}
NUMBERS = {name: list(_numbers(data)) for name, data in ROBOTS.items()}
EXTREMES = [0.0, -1.0, 1e-300, 1e-12, 1e6, 1e12, 1e300, -1e300]


@FUZZ
@given(
    robot=st.sampled_from(sorted(ROBOTS)),
    index=st.integers(min_value=0, max_value=10**6),
    value=st.sampled_from(EXTREMES),
)
def test_extreme_robot_file_exports_or_is_refused(robot: str, index: int, value: float) -> None:
    data = copy.deepcopy(ROBOTS[robot])
    *parents, last = NUMBERS[robot][index % len(NUMBERS[robot])]
    target = data
    for key in parents:
        target = target[key]
    target[last] = value
    _FOLDERS.append(Path(tempfile.mkdtemp(prefix="kinergy-fuzz-export-")))
    folder = _FOLDERS[-1]
    (folder / "m.toml").write_text(tomli_w.dumps(data), encoding="utf-8")
    for fmt in ("urdf", "mjcf"):
        outcome = run_case(
            ["robot", "export", "m.toml", "--format", fmt, "--out", f"x.{fmt}"],
            folder,
            outputs=[f"x.{fmt}"],
        )
        if outcome.status == 0:
            values = set((folder / f"x.{fmt}").read_text(encoding="utf-8").split('"'))
            assert not {"nan", "inf", "-inf"} & values
