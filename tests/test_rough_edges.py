"""A first day's rough edges (issue 37), each as a user met it and as it ends now: swapped
arguments named as such, a payload that does not fit named as the payload, unknown built-in
motions listed, missing output folders refused, R² of joints that did not move explained, one
compile notice, one spelling and one unit style."""

from __future__ import annotations

import ast
import re
from pathlib import Path

import numpy as np
import pytest
from clicase import run_case

import kinergy
from kinergy.cli import main

DATASETS = Path(__file__).resolve().parents[2] / "shared" / "datasets" / "ur10e-innopolis"
PTP = DATASETS / "validation_data" / "ur-20_01_17-ptp_10_points.csv"
COLUMNS = "timestamp,actual_q:6,actual_qd:6,actual_current:6,target_current:6,target_moment:6"
real = pytest.mark.skipif(not PTP.exists(), reason="shared datasets not available")


def _error(args: list[str], capsys: pytest.CaptureFixture[str]) -> str:
    """The one line ``kinergy ARGS`` refuses with (exit 1)."""
    assert main(args) == 1
    # the compile notice: a load from numba's cache can take over 2 s on a busy machine
    lines = [x for x in capsys.readouterr().err.splitlines() if "preparing the dynamics" not in x]
    assert len(lines) == 1 and lines[0].startswith("kinergy: error: "), lines
    return lines[0]


@pytest.mark.parametrize("command", ["validate", "energy"])
def test_a_log_and_a_model_given_the_other_way_round_are_named_swapped(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], command: str
) -> None:
    log, model = tmp_path / "run.csv", tmp_path / "model.toml"
    log.write_text("timestamp actual_q_0\n0 0\n0.1 0\n")
    assert main(["-q", "robot", "show", "ur5e"]) == 0  # a robot file to give as the model
    capsys.readouterr()
    model.write_text('name = "x"\n')
    err = _error([command, str(log), str(model)], capsys)
    assert f"MODEL {log} looks like a log and LOG {model} like a robot file" in err
    assert (
        f"the arguments are swapped; the model comes first: kinergy {command} {model} {log}" in err
    )
    assert "TOML" not in err and "Expected '='" not in err


def test_an_unknown_built_in_motion_lists_the_built_in_ones(
    capsys: pytest.CaptureFixture[str],
) -> None:
    for args in (["energy", "ur10e", "test-c"], ["validate", "ur10e", "test-c"]):
        err = _error(args, capsys)
        assert "test-c: no such file or folder, nor a built-in motion (test-a, test-b)" in err


@real
def test_a_payload_that_does_not_fit_a_ur10e_log_is_named_as_the_payload(
    capsys: pytest.CaptureFixture[str],
) -> None:
    """Before: "looks like ur16e" (a bare UR16e fits a UR10e with 3 kg better than the UR10e)."""
    args = ["energy", "ur10e", str(PTP), "--columns", COLUMNS, "--payload", "3"]
    err = _error(args, capsys)
    assert "the payload 3 kg at [0, 0, 0] m does not fit this log" in err
    assert "ur10e's model fits it without that payload; check --payload" in err
    assert "ur16e" not in err
    assert main(["-q", "energy", "ur10e", str(PTP), "--columns", COLUMNS]) == 0  # without: fine


#: a command that writes, with the output flag pointed into a folder that does not exist
WRITERS = [
    ["simulate", "ur5e", "--trajectory", "test-a", "--out", "{missing}/a.csv"],
    ["robot", "export", "ur5e", "--format", "urdf", "--out", "{missing}/ur5e.urdf"],
    ["energy", "ur5e", "test-a", "--trace", "{missing}/trace.csv"],
    ["energy", "ur5e", "test-a", "--plot", "{missing}/power.png"],
    ["validate", "ur5e", "test-b", "--plots", "{missing}/plots"],
    ["demo", "--out", "{missing}/demo"],
    ["optimize", "ur5e", "test-a", "--urscript", "{missing}/a.script"],
    ["excite", "ur5e", "--out", "{missing}/e.csv"],
    ["identify", "{log}", "--robot", "ur5e", "--out", "{missing}/m.toml"],
    ["convert", "{log}", "--to", "csv", "{missing}/a.csv"],
]


@pytest.mark.parametrize("args", WRITERS, ids=lambda a: " ".join(a[:2]))
def test_an_output_in_a_folder_that_does_not_exist_is_refused(
    tmp_path: Path, args: list[str]
) -> None:
    """Before: the folders were created silently (a mistyped path made a tree of them)."""
    log = tmp_path / "a.csv"
    log.write_text("timestamp actual_q_0 actual_q_1 actual_q_2 actual_q_3 actual_q_4 actual_q_5\n")
    given = [a.format(missing="no/such", log="a.csv") for a in args]
    refused = run_case(given, tmp_path, refuse=True)
    assert "no such folder no/such" in refused.err, refused.err
    assert not (tmp_path / "no").exists()


def test_the_python_api_refuses_a_missing_folder_too(tmp_path: Path) -> None:
    log = tmp_path / "a.csv"
    log.write_text("timestamp actual_q_0\n")
    with pytest.raises(kinergy.KinergyError, match="no such folder"):
        kinergy.identify([log], "ur5e", out=tmp_path / "no" / "m.toml")
    assert not (tmp_path / "no").exists()


def test_r2_of_a_joint_that_did_not_move_is_not_printed_but_explained() -> None:
    """The fit table (identify) says "not excited" where validate does: a joint whose position
    spans under EXCITED_RANGE has an R² that means nothing (it was printed, negative)."""
    from kinergy.identification.metrics import EXCITED_RANGE, ExcitedSums

    rng = np.random.default_rng(5)
    q = np.column_stack([np.linspace(0, 1, 500), np.full(500, 0.3) + 1e-3 * rng.random(500)])
    measured = rng.normal(0.0, 1.0, (500, 2))
    predicted = measured + rng.normal(0.0, 2.0, (500, 2))  # R² far below 0 on both
    sums = ExcitedSums(2)
    sums.add(measured[:200], predicted[:200], q[:200])
    sums.add(measured[200:], predicted[200:], q[200:])
    moved, still = sums.metrics() or ()
    assert moved.r2 < 0 and moved.note is None  # moved: its (bad) R² is printed
    assert np.isnan(still.r2) and still.note == "not excited"
    assert np.ptp(q[:, 1]) < EXCITED_RANGE


JOINT_1 = DATASETS / "jointwise_motion" / "ur-20_01_22-joint_1.csv"


@pytest.mark.skipif(not JOINT_1.exists(), reason="shared datasets not available")
def test_identify_s_fit_table_says_not_excited_where_a_joint_did_not_move(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """The UR10e run where only the base moves: identify's fit table says "not excited" for
    the joints that stood still, as validate does, instead of their (negative) R²."""
    model = tmp_path / "m.toml"
    args = ["identify", str(JOINT_1), "--robot", "ur10e", "--columns", COLUMNS]
    code = main([*args, "--out", str(model), "--accept", "all"])
    out, err = capsys.readouterr()
    assert code == 0, err
    fit = out[out.index("Fit on the identification logs") :]
    rows = [
        line.split() for line in fit.splitlines() if line.startswith(("shoulder", "elbow", "wrist"))
    ]
    assert rows and all(not re.fullmatch(r"-\d+\.\d+", r[-1]) for r in rows), fit
    assert "not excited" in fit


def test_the_compile_notice_is_said_once_whatever_the_kernels(
    capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    from kinergy.dynamics import launch

    monkeypatch.setattr(launch, "_NOTICE_AFTER", 0.0)
    monkeypatch.setattr(launch, "_noticed", threading_event())
    import time

    for kernel in (launch.Kernel.RNEA, launch.Kernel.REGRESSOR, launch.Kernel.GRADIENT):
        launch._with_notice(lambda: time.sleep(0.2), kernel)
    err = capsys.readouterr().err
    assert err.count("kinergy: preparing the dynamics kernels") == 1, err
    assert "once per install: 10-113 s of processor time" in err


def threading_event() -> object:
    import threading

    return threading.Event()


_FORBIDDEN = {
    "kg m^2": "kg m²",
    "+-": "±",
    "R^2": "R²",
    "optimization": "optimisation",
    "optimizer": "optimiser",
    "optimizing": "optimising",
}
#: "optimized" as a word of prose (not the JSON key or a parameter: ``optimized :``, ``E_optimized``)
_OPTIMIZED = re.compile(r"(?<![\w`'\"])optimized(?![\w`'\".]|\s*:)")


def _strings(path: Path) -> list[tuple[int, str]]:
    """The string literals of a Python file that reach a user (messages, help, table headers,
    f-strings' text), with their lines; docstrings and comments left out."""
    tree = ast.parse(path.read_text(encoding="utf-8"))
    docs = {
        id(node.value)
        for node in ast.walk(tree)
        if isinstance(node, ast.Expr) and isinstance(node.value, ast.Constant)
    }
    return [
        (node.lineno, node.value)
        for node in ast.walk(tree)
        if isinstance(node, ast.Constant) and isinstance(node.value, str) and id(node) not in docs
    ]


def test_every_output_spells_one_way_and_writes_units_one_way() -> None:
    """British spelling (the majority of the prose: optimised, optimisation, optimiser; the
    command and its JSON keys stay `optimize`, `optimized`) and kg m², ±, R² in every string the
    package prints (messages, help, tables, plot labels)."""
    package = Path(kinergy.__file__).parent
    found = []
    for path in sorted(package.rglob("*.py")):
        for line, text in _strings(path):
            for wrong, right in _FORBIDDEN.items():
                if wrong == "+-" and len(text) <= 3:
                    continue  # the characters a number's sign may be ("+-."), not a ± sign
                if wrong in text:
                    found.append(f"{path.relative_to(package)}:{line}: {wrong!r} (write {right!r})")
            if text != "optimized" and _OPTIMIZED.search(text):  # the JSON key is a name
                found.append(f"{path.relative_to(package)}:{line}: 'optimized' (write 'optimised')")
    assert not found, "\n".join(found[:20])


def _steps() -> None:
    from kinergy.cli.common import progress

    with progress() as say:
        say("checking the reach")
        for k in range(4):
            say(f"placement {k + 1}", done=k, total=4)


def test_long_work_shows_a_fraction_and_the_time_left_on_a_terminal_and_nothing_on_a_pipe(
    capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.delenv("FORCE_COLOR", raising=False)
    monkeypatch.delenv("TTY_COMPATIBLE", raising=False)
    _steps()  # pytest's stderr is a pipe
    assert capsys.readouterr().err == ""
    monkeypatch.setenv("FORCE_COLOR", "1")  # rich takes stderr for a terminal
    monkeypatch.setenv("COLUMNS", "120")
    _steps()
    err = re.sub(r"\x1b\[[0-9;?]*[a-zA-Z]", "", capsys.readouterr().err)
    assert "placement 4" in err and "4/4" in err and "left" in err
    assert "checking the reach" in err
