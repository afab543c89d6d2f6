"""kinergy.checks: each check returns the typed value or one coded line; KinergyError's code
survives prefixing and pickling; a Message keeps its code through a prefix."""

from __future__ import annotations

import doctest
import enum
import pickle

import numpy as np
import pytest

from kinergy import checks, messages
from kinergy.errors import Code, KinergyError
from kinergy.messages import Message, Messages, coded


class Colour(enum.StrEnum):
    RED = "red"
    BLUE = "blue"


def test_doctests_of_the_checks_and_messages_hold() -> None:
    for module in (checks, messages):
        result = doctest.testmod(module)
        assert result.attempted > 0 and result.failed == 0


@pytest.mark.parametrize(
    ("value", "bounds", "message"),
    [
        (-1, {"ge": 0.0}, "x: must be a finite number >= 0, got -1"),
        (0.0, {"gt": 0.0}, "x: must be a finite number > 0, got 0"),
        (float("nan"), {}, "x: must be a finite number, got nan"),
        (float("inf"), {"gt": 0.0}, "x: must be a finite number > 0, got inf"),
        ("3", {}, "x: must be a finite number, got '3'"),
        (True, {}, "x: must be a finite number, got True"),
        (2.0, {"ge": 0.0, "le": 1.0}, "x: must be a finite number >= 0 and <= 1, got 2"),
        (-200.0, {"size": 100.0}, "x: must be a finite number of size at most 100, got -200"),
    ],
)
def test_number_refuses_in_one_line_with_its_code(
    value: object, bounds: dict[str, float], message: str
) -> None:
    with pytest.raises(KinergyError) as err:
        checks.number(value, "x", **bounds)
    assert str(err.value) == message
    assert err.value.code == Code.NUMBER


def test_number_returns_a_float_at_its_bounds() -> None:
    out = checks.number(np.int64(1), "x", ge=1, le=1)
    assert out == 1.0 and type(out) is float
    assert checks.number(0.5, "x", gt=0.0, lt=1.0) == 0.5
    assert checks.number(-100, "x", size=100) == -100.0


def test_vector_returns_a_read_only_float_array_or_names_the_count() -> None:
    out = checks.vector([1, 2, 3], "g", length=3)
    assert out.dtype == np.float64 and out.shape == (3,) and not out.flags.writeable
    with pytest.raises(KinergyError, match=r"^g: must be 3 finite numbers, got \[1, 2\]$") as err:
        checks.vector([1, 2], "g", length=3)
    assert err.value.code == Code.SHAPE
    with pytest.raises(KinergyError, match=r"got shape \(2, 2\)") as err:
        checks.vector(np.eye(2), "g")
    assert err.value.code == Code.SHAPE
    with pytest.raises(KinergyError, match="must be 2 finite numbers, each >= 0, got") as err:
        checks.vector([1.0, -1.0], "g", length=2, ge=0.0)
    assert err.value.code == Code.NUMBER
    with pytest.raises(KinergyError, match="got 'ab'"):
        checks.vector("ab", "g")


def test_known_keys_lists_the_unknown_and_the_allowed() -> None:
    data = {"a": 1}
    assert checks.known_keys(data, {"a", "b"}, "t") is data
    with pytest.raises(KinergyError) as err:
        checks.known_keys({"a": 1, "zz": 2}, {"a", "b"}, "t")
    assert str(err.value) == "t: unknown field(s) 'zz' (allowed: a, b)"
    assert err.value.code == Code.UNKNOWN_KEY
    with pytest.raises(KinergyError, match="t: must be a table, got list"):
        checks.known_keys([1], {"a"}, "t")


def test_choice_parses_into_the_enum() -> None:
    assert checks.choice("red", Colour, "--colour") is Colour.RED
    assert checks.choice(Colour.BLUE, Colour, "--colour") is Colour.BLUE
    with pytest.raises(KinergyError) as err:
        checks.choice("green", Colour, "--colour")
    assert str(err.value) == "--colour: must be one of red, blue, got 'green'"
    assert err.value.code == Code.UNKNOWN_CHOICE


def test_an_error_keeps_its_code_through_prefix_and_pickle() -> None:
    err = KinergyError("bad", Code.DISAGREES)
    again = pickle.loads(pickle.dumps(err.prefixed("file.urdf")))
    assert str(again) == "file.urdf: bad" and again.code == Code.DISAGREES
    assert KinergyError("plain").code == Code.INVALID


def test_warnings_are_picked_by_code_not_text() -> None:
    said = Messages()
    said.warn("a payload the model lacks", Code.PAYLOAD_MISSING)
    said.warn("a payload the model lacks, said in other words")
    prefixed = [
        Message(w).prefixed("run.csv") if isinstance(w, Message) else w for w in said.warnings
    ]
    assert coded(prefixed, Code.PAYLOAD_MISSING) == ["run.csv: a payload the model lacks"]


def test_an_identified_payload_takes_the_payload_warning_by_its_code() -> None:
    """``identify --payload-only``: the logs' "payload the model lacks" is what it identifies,
    so it is routine there (a note); a warning of other words is left a warning, whatever it
    says."""
    import kinergy
    from kinergy.logs.checks import LogChecks
    from kinergy.logs.reading import InputLogs
    from kinergy.workflows.identify import PayloadRun

    lacks = Message(
        "fits the arm carrying 2 kg at [0, 0, 0.05] m that the model lacks", Code.PAYLOAD_MISSING
    )
    other = "a warning that mentions that the model lacks something else"
    checks = LogChecks(log="run.csv", warnings=(lacks.prefixed("run.csv"), other))
    run = PayloadRun(kinergy.load_robot("ur5e"), None, InputLogs(checks=[checks]))  # type: ignore[arg-type]
    assert run.lacks == [f"run.csv: {lacks}"]
    assert run.warnings == [other]
