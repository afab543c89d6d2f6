"""Property tests of the log reader: any valid record.py-layout log round-trips, and any one
corruption of it is rejected with one line naming the file and, where it applies, the line and the
column.

Hypothesis draws logs with 1-3 vector signals of 1-7 columns and up to 2 scalar columns in any
order, space or comma separated, 2-12 rows of finite values up to 1e300 printed in one of three
formats, and strictly increasing time stamps. Line numbers are 1-based and count the header;
data row r (0-based) is file line r + 2.
"""

from __future__ import annotations

import itertools
import string
from collections.abc import Callable, Sequence
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st
from hypothesis.extra import numpy as hnp

from kinergy.cli import main
from kinergy.errors import KinergyError
from kinergy.io.rtde import read_log

VECTORS = ("actual_q", "actual_qd", "target_q", "target_moment", "actual_current")
SCALARS = ("robot_mode", "runtime_state", "actual_robot_voltage")
#: how values are printed: exact (repr), record.py's 10 significant digits, scientific
FORMATS = ("{!r}", "{:.10g}", "{:.6e}")

FAST = settings(max_examples=60, deadline=None)


@dataclass(frozen=True)
class Table:
    """A log as text cells: ``layout`` is (signal, width) with width 0 for a scalar column."""

    sep: str
    layout: tuple[tuple[str, int], ...]
    rows: tuple[tuple[str, ...], ...]

    @property
    def names(self) -> list[str]:
        out = ["timestamp"]
        for name, width in self.layout:
            out.extend([name] if width == 0 else [f"{name}_{k}" for k in range(width)])
        return out

    @property
    def spec(self) -> str:
        """The ``--columns`` spec of this layout."""
        return ",".join(["timestamp"] + [n if w == 0 else f"{n}:{w}" for n, w in self.layout])

    def line(self, r: int) -> str:
        return self.sep.join(self.rows[r])

    def text(self, *, header: bool = True) -> str:
        lines = [self.sep.join(self.names)] if header else []
        lines += [self.line(r) for r in range(len(self.rows))]
        return "\n".join(lines) + "\n"

    def values(self) -> np.ndarray:
        """The numbers the cells print, (N, K)."""
        return np.array([[float(c) for c in row] for row in self.rows])


@dataclass(frozen=True)
class Case:
    """A file's text, the ``--columns`` spec to read it with, and what its error must say."""

    text: str
    columns: str | None
    expect: tuple[str, ...]


_finite = st.floats(-1e300, 1e300, allow_nan=False, allow_infinity=False)


@st.composite
def tables(
    draw: st.DrawFn, layout: Sequence[tuple[str, int]] | None = None, max_rows: int = 12
) -> Table:
    sep = draw(st.sampled_from([" ", ","]))
    if layout is None:
        vectors = draw(st.lists(st.sampled_from(VECTORS), min_size=1, max_size=3, unique=True))
        scalars = draw(st.lists(st.sampled_from(SCALARS), max_size=2, unique=True))
        layout = draw(
            st.permutations(
                [(v, draw(st.integers(1, 7))) for v in vectors] + [(s, 0) for s in scalars]
            )
        )
    n_rows = draw(st.integers(2, max_rows))
    n_cols = sum(max(w, 1) for _, w in layout)
    fmt = draw(st.sampled_from(FORMATS))
    t0 = draw(st.floats(-10.0, 1000.0))
    # periods up to 0.5 s: a step of 1 s, printed and read back a hair above 1, is refused as
    # ambiguous (1 Hz in s or 1 kHz in ms, kinergy.io.log.time_unit) by design
    steps = draw(st.lists(st.floats(1e-3, 0.5), min_size=n_rows - 1, max_size=n_rows - 1))
    t = [fmt.format(float(x)) for x in t0 + np.concatenate([[0.0], np.cumsum(steps)])]
    parsed = [float(x) for x in t]
    assume(all(b > a for a, b in itertools.pairwise(parsed)))
    values = draw(hnp.arrays(np.float64, (n_rows, n_cols), elements=_finite))
    rows = tuple((t[r], *(fmt.format(float(x)) for x in values[r])) for r in range(n_rows))
    return Table(sep, tuple(layout), rows)


def _with_row(table: Table, r: int, row: Sequence[str]) -> Table:
    return replace(table, rows=(*table.rows[:r], tuple(row), *table.rows[r + 1 :]))


def _with_cell(table: Table, r: int, c: int, token: str) -> Table:
    row = list(table.rows[r])
    row[c] = token
    return _with_row(table, r, row)


_bad_tokens = st.one_of(
    st.text(alphabet=string.ascii_letters, min_size=1, max_size=6),
    st.sampled_from(
        ["nan", "NaN", "-nan", "inf", "-inf", "+inf", "Infinity", "1.2.3", "1e", "--1", "0x1A", "."]
    ),
)


@st.composite
def bad_cell(draw: st.DrawFn) -> Case:
    """One cell replaced by a non-numeric token, or emptied (comma files only)."""
    table = draw(tables())
    r = draw(st.integers(0, len(table.rows) - 1))
    c = draw(st.integers(0, len(table.names) - 1))
    token = draw(_bad_tokens | st.just("")) if table.sep == "," else draw(_bad_tokens)
    what = "missing value" if token == "" else f"not a finite number: {token!r}"
    expect = (f"line {r + 2}, column {c + 1} ({table.names[c]}): {what}",)
    return Case(_with_cell(table, r, c, token).text(), None, expect)


def _pandas_finite(token: str) -> bool:
    value = pd.to_numeric(pd.Series([token]), errors="coerce").iloc[0]
    return bool(np.isfinite(value))


@st.composite
def truncated(draw: st.DrawFn) -> Case:
    """The last line cut inside it, losing at least its last field (a cut that keeps every field
    and only shortens the last number is indistinguishable from a valid file)."""
    table = draw(tables())
    last = table.line(len(table.rows) - 1)
    cut = draw(st.integers(1, last.rindex(table.sep) + 1))
    kept = last[:cut]
    n_sep = kept.count(table.sep)
    if kept.endswith(table.sep) or not _pandas_finite(kept.split(table.sep)[-1]):
        column = n_sep + 1  # an empty or a half-written field
    else:
        column = n_sep + 2  # the first field that is gone
    text = table.text()[: -len(last) - 1] + kept + draw(st.sampled_from(["", "\n"]))
    line = len(table.rows) + 1
    return Case(text, None, (f"line {line}, column {column} ({table.names[column - 1]})",))


@st.composite
def extra_field(draw: st.DrawFn) -> Case:
    """One more number on one line."""
    table = draw(tables())
    r = draw(st.integers(0, len(table.rows) - 1))
    at = draw(st.integers(0, len(table.names)))
    token = repr(draw(_finite))
    row = list(table.rows[r])
    row.insert(at, token)
    bad = _with_row(table, r, row)
    k = len(table.names)
    # pandas takes the width from the first data line: an extra field there makes every row
    # "too short" and only the counts can be named; later, the line is named
    expect = (f"{k + 1} fields", f"names {k}") if r == 0 else (f"line {r + 2}",)
    return Case(bad.text(), None, expect)


@st.composite
def bad_timestamps(draw: st.DrawFn) -> Case:
    """The time stamp of one row repeats the previous one or goes back before it."""
    table = draw(tables())
    r = draw(st.integers(1, len(table.rows) - 1))
    previous = table.rows[r - 1][0]
    if draw(st.booleans()):
        kind, token = "repeats", previous
    else:
        kind = "goes back"
        token = repr(float(previous) - draw(st.floats(1e-3, 100.0)))
        assume(float(token) < float(previous))
    expect = (f"line {r + 2}: timestamp {kind}",)
    return Case(_with_cell(table, r, 0, token).text(), None, expect)


@st.composite
def headerless(draw: st.DrawFn) -> Case:
    """The header line removed and no column spec given."""
    table = draw(tables())
    return Case(table.text(header=False), None, ("no header line", "--columns"))


@st.composite
def wrong_spec(draw: st.DrawFn) -> Case:
    """A headerless file read with a column spec of another column count."""
    table = draw(tables())
    layout = list(table.layout)
    change = draw(
        st.sampled_from(["width", "add", "drop"] if len(layout) > 1 else ["width", "add"])
    )
    i = draw(st.integers(0, len(layout) - 1))
    if change == "add":
        width = draw(st.sampled_from([0, 1, 3]))
        layout.insert(i, ("speed_scaling", 0) if width == 0 else ("joint_control_output", width))
    elif change == "drop":
        del layout[i]
    else:
        vectors = [k for k, (_, w) in enumerate(layout) if w > 0]
        assume(vectors)
        i = draw(st.sampled_from(vectors))
        name, width = layout[i]
        new = draw(st.integers(1, 9).filter(lambda w: w != width))
        layout[i] = (name, new)
    spec_table = Table(table.sep, tuple(layout), ())
    have, named = len(table.names), len(spec_table.names)
    expect = (f"rows have {have} fields", f"--columns spec names {named}")
    return Case(table.text(header=False), spec_table.spec, expect)


KINDS: dict[str, Callable[[], st.SearchStrategy[Case]]] = {
    "cell": bad_cell,
    "truncated": truncated,
    "extra field": extra_field,
    "timestamps": bad_timestamps,
    "headerless": headerless,
    "wrong spec": wrong_spec,
}

_names = itertools.count()


@pytest.fixture(scope="module")
def workdir(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return tmp_path_factory.mktemp("logs")


def _save(directory: Path, text: str) -> Path:
    path = directory / f"log{next(_names)}.csv"
    path.write_text(text, encoding="utf-8", newline="")
    return path


def _rejects(path: Path, columns: str | None) -> str:
    """read_log must raise a one-line KinergyError that starts with the path; its message."""
    with pytest.raises(KinergyError) as info:
        read_log(path, columns=columns)
    message = str(info.value)
    assert "\n" not in message and "\r" not in message, message
    assert message.startswith(f"{path}: "), message
    return message


# --- valid logs ---------------------------------------------------------------------------------


@FAST
@given(table=tables(), header=st.booleans())
def test_valid_logs_round_trip(workdir: Path, table: Table, header: bool) -> None:
    path = _save(workdir, table.text(header=header))
    log = read_log(path, columns=None if header else table.spec)
    expected = table.values()
    assert log.path == str(path) and len(log) == len(table.rows)
    np.testing.assert_array_equal(log.t, expected[:, 0])
    col = 1
    assert set(log.signals) == {name for name, _ in table.layout}
    for name, width in table.layout:
        if width == 0:
            assert log[name].shape == (len(table.rows),)
            np.testing.assert_array_equal(log[name], expected[:, col])
            col += 1
        else:
            assert log[name].shape == (len(table.rows), width)
            np.testing.assert_array_equal(log[name], expected[:, col : col + width])
            col += width


# --- one corruption each: read_log names it -----------------------------------------------------


def _check(workdir: Path, case: Case) -> None:
    path = _save(workdir, case.text)
    message = _rejects(path, case.columns)
    for part in case.expect:
        assert part in message, (part, message)


@FAST
@given(case=bad_cell())
def test_a_non_numeric_cell_names_its_line_and_column(workdir: Path, case: Case) -> None:
    _check(workdir, case)


@FAST
@given(case=truncated())
def test_a_truncated_last_line_is_named(workdir: Path, case: Case) -> None:
    _check(workdir, case)


@FAST
@given(case=extra_field())
def test_an_extra_field_is_rejected(workdir: Path, case: Case) -> None:
    _check(workdir, case)


@FAST
@given(case=bad_timestamps())
def test_time_stamps_that_repeat_or_go_back_name_the_line(workdir: Path, case: Case) -> None:
    _check(workdir, case)


@settings(max_examples=25, deadline=None)
@given(case=headerless())
def test_a_headerless_file_needs_a_column_spec(workdir: Path, case: Case) -> None:
    _check(workdir, case)


@FAST
@given(case=wrong_spec())
def test_a_column_spec_of_the_wrong_width_names_both_counts(workdir: Path, case: Case) -> None:
    _check(workdir, case)


# --- the command line ---------------------------------------------------------------------------

_cli_settings = settings(
    max_examples=40, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture]
)


@_cli_settings
@given(case=st.sampled_from(sorted(KINDS)).flatmap(lambda kind: KINDS[kind]()))
def test_energy_on_a_corrupted_log_is_one_error_line(
    workdir: Path, capsys: pytest.CaptureFixture[str], case: Case
) -> None:
    capsys.readouterr()  # examples share the fixture: start from empty streams
    assume(case.columns is None)  # a spec's widths are checked against the robot first
    path = _save(workdir, case.text)
    args = ["energy", "ur5e", str(path)] + (
        [] if case.columns is None else ["--columns", case.columns]
    )
    assert main(args) == 1
    out, err = capsys.readouterr()
    assert out == ""
    assert err.startswith(f"kinergy: error: {path}: ") and err.count("\n") == 1, err
    for part in case.expect:
        assert part in err, (part, err)


@_cli_settings
@given(
    table=tables(layout=[("actual_q", 7), ("actual_qd", 7)]),
    header=st.booleans(),
    source=st.sampled_from(["auto", "actual"]),
)
def test_a_seven_joint_log_is_rejected_for_the_ur5e(
    workdir: Path, capsys: pytest.CaptureFixture[str], table: Table, header: bool, source: str
) -> None:
    capsys.readouterr()
    path = _save(workdir, table.text(header=header))
    args = ["energy", "ur5e", str(path), "--source", source]
    assert main(args + ([] if header else ["--columns", table.spec])) == 1
    err = capsys.readouterr().err
    assert err.count("\n") == 1, err
    if header:  # the file's 7 joints against the robot's 6
        assert err.startswith(f"kinergy: error: {path}: ") and "has 7 joints" in err, err
    else:  # the spec's 7 columns refused before the file is read
        assert "--columns: actual_q:7 but the robot has 6 joints" in err, err
