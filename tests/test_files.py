"""The output layer: files written whole or not at all, never over an input or a non-regular file,
folders built beside their target, temporaries gone after an error, Ctrl-C or SIGTERM."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import pytest

import kinergy
from kinergy.errors import KinergyError
from kinergy.files import (
    MARKER,
    atomic_folder,
    atomic_write,
    check_output,
    check_outputs,
    read_toml,
)


def _leftovers(folder: Path) -> list[str]:
    return sorted(p.name for p in folder.iterdir() if p.name.startswith("."))


def test_a_failed_write_keeps_the_old_file_and_leaves_no_temporary(tmp_path: Path) -> None:
    target = tmp_path / "model.toml"
    target.write_text("# kinergy: old")

    def fail(fh: object) -> None:
        raise RuntimeError("boom")

    with pytest.raises(RuntimeError):
        atomic_write(target, fail)
    assert target.read_text() == "# kinergy: old"
    assert _leftovers(tmp_path) == []
    atomic_write(target, lambda fh: fh.write("new"))
    assert target.read_text() == "new" and _leftovers(tmp_path) == []


@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="needs FIFOs")
def test_non_regular_targets_are_refused_and_left_alone(tmp_path: Path) -> None:
    fifo = tmp_path / "pipe"
    os.mkfifo(fifo)
    real = tmp_path / "real.csv"
    real.write_text("keep")
    link = tmp_path / "link.csv"
    link.symlink_to(real)
    for path, words in (
        (fifo, "not a regular file"),
        (link, "symbolic link"),
        (tmp_path, "a folder"),
        (Path("/dev/null"), "not a regular file"),
    ):
        with pytest.raises(KinergyError, match=words):
            atomic_write(path, lambda fh: fh.write("x"))
    assert real.read_text() == "keep" and link.is_symlink()
    assert Path("/dev/null").exists() and not Path("/dev/null").is_file()


def test_an_output_may_not_be_an_input_or_another_output(tmp_path: Path) -> None:
    log = tmp_path / "log.csv"
    log.write_text("timestamp\n")
    with pytest.raises(KinergyError, match=r"--out .*log.csv: is also an input"):
        check_outputs([("--out", log)], [log])
    # the same file by another spelling
    with pytest.raises(KinergyError, match="is also an input"):
        check_outputs([("--out", tmp_path / "." / "log.csv")], [log])
    with pytest.raises(KinergyError, match="is also the output of --out"):
        check_outputs([("--out", tmp_path / "a"), ("--urscript", tmp_path / "a")], [])
    check_outputs([("--out", tmp_path / "b"), ("--plot", None)], [log])
    assert check_output(tmp_path / "new.csv") == tmp_path / "new.csv"


def test_a_folder_is_built_beside_and_renamed_into_place(tmp_path: Path) -> None:
    target = tmp_path / "report"
    with atomic_folder(target) as folder:
        (folder / "report.html").write_text("<html>")
        assert not target.exists()
    assert (target / "report.html").read_text() == "<html>" and (target / MARKER).exists()
    # a failure leaves the earlier report as it was and nothing beside it
    with pytest.raises(RuntimeError), atomic_folder(target) as folder:
        (folder / "report.html").write_text("half")
        raise RuntimeError("boom")
    assert (target / "report.html").read_text() == "<html>"
    assert _leftovers(tmp_path) == []
    # a folder kinergy wrote may be replaced; a user's folder may not
    with atomic_folder(target) as folder:
        (folder / "report.html").write_text("again")
    assert (target / "report.html").read_text() == "again"
    mine = tmp_path / "mine"
    mine.mkdir()
    (mine / "thesis.tex").write_text("precious")
    with pytest.raises(KinergyError, match="holds thesis.tex, which kinergy did not write"):
        with atomic_folder(mine):
            pass
    assert (mine / "thesis.tex").read_text() == "precious"


def test_a_folder_kinergy_wrote_is_kept_once_anything_else_is_put_or_changed_in_it(
    tmp_path: Path,
) -> None:
    """The marker lists every file kinergy wrote (SHA-256): a file added anywhere below the
    folder, or one of kinergy's changed, makes the folder the user's; an old marker without the
    list vouches for nothing."""
    target = tmp_path / "demo"
    with atomic_folder(target) as folder:
        (folder / "logs").mkdir()
        (folder / "logs" / "test-a.csv").write_text("t,q\n")
        (folder / "report.html").write_text("<html>")
    for change in ("add", "edit", "old marker"):
        if change == "add":
            (target / "logs" / "my-notes.txt").write_text("mine")
            what = "logs/my-notes.txt"
        elif change == "edit":
            (target / "logs" / "my-notes.txt").unlink()
            (target / "report.html").write_text("<html> my edits")
            what = "report.html"
        else:
            (target / "report.html").write_text("<html>")
            (target / MARKER).write_text("written by kinergy; it may replace this folder\n")
            what = "logs/test-a.csv"
        with pytest.raises(KinergyError, match=f"holds {what}, which kinergy did not write"):
            with atomic_folder(target):
                pass
        assert (target / "logs" / "test-a.csv").read_text() == "t,q\n"


def test_toml_that_nests_too_deeply_is_one_line(tmp_path: Path) -> None:
    deep = tmp_path / "deep.toml"
    deep.write_text("x = " + "[" * 50_000 + "]" * 50_000 + "\n")
    with pytest.raises(KinergyError, match="nest too deeply"):
        read_toml(deep, "robot file")


_SLOW_WRITER = textwrap.dedent(
    """
    import signal, sys, time
    from kinergy.files import atomic_write, terminate_on_signals

    # A shell's background job starts with SIGINT ignored; Ctrl-C at a terminal is not.
    signal.signal(signal.SIGINT, signal.default_int_handler)

    def slow(fh):
        fh.write("partial")
        fh.flush()
        print("writing", flush=True)
        time.sleep(30)

    with terminate_on_signals():
        atomic_write(sys.argv[1], slow)
    """
)


def _writer(script: str, folder: Path, first_line: str) -> tuple[subprocess.Popen[str], Path]:
    """Start ``script`` on ``folder/out.csv`` (which holds "before") and wait for its first line
    of output, ``first_line``: the moment to send it a signal."""
    target = folder / "out.csv"
    target.write_text("before")
    proc = subprocess.Popen(
        [sys.executable, "-c", script, str(target)],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        env={**os.environ, "PYTHONPATH": os.pathsep.join(sys.path)},
    )
    assert proc.stdout is not None
    assert proc.stdout.readline().strip() == first_line
    return proc, target


@pytest.mark.parametrize("sig", [signal.SIGTERM, signal.SIGINT])
def test_a_signal_mid_write_leaves_the_old_file_and_no_temporary(tmp_path: Path, sig: int) -> None:
    proc, target = _writer(_SLOW_WRITER, tmp_path, "writing")
    assert _leftovers(tmp_path)  # the temporary exists while it writes
    proc.send_signal(sig)
    start = time.monotonic()
    proc.wait(timeout=20)
    assert time.monotonic() - start < 10
    assert proc.returncode != 0
    assert target.read_text() == "before"
    assert _leftovers(tmp_path) == []


_SWALLOWED = textwrap.dedent(
    """
    import ctypes, signal, sys, time
    from kinergy.files import Terminated, atomic_write, terminate_on_signals

    signal.signal(signal.SIGINT, signal.default_int_handler)
    libc = ctypes.CDLL(None)
    compare = ctypes.CFUNCTYPE(ctypes.c_int, ctypes.c_void_p, ctypes.c_void_p)

    def slow(a, b):  # C calls back into Python, as llvmlite does while numba compiles
        print("in callback", flush=True)
        time.sleep(30)
        return 0

    values = (ctypes.c_int * 2)(1, 2)
    try:
        with terminate_on_signals():
            libc.qsort(values, 2, ctypes.sizeof(ctypes.c_int), compare(slow))
            print("after callback", flush=True)
            atomic_write(sys.argv[1], lambda fh: fh.write("new"))
    except (Terminated, KeyboardInterrupt) as exc:
        print(type(exc).__name__, flush=True)
        sys.exit(143)
    """
)


@pytest.mark.parametrize("sig", [signal.SIGTERM, signal.SIGINT])
def test_a_signal_dropped_by_a_c_callback_still_stops_the_write(tmp_path: Path, sig: int) -> None:
    """A signal's exception raised inside a ctypes callback is printed and dropped by ctypes (a
    SIGTERM during numba's compile once let a killed command finish and print a traceback): the
    signal is raised again before the output is renamed into place."""
    proc, target = _writer(_SWALLOWED, tmp_path, "in callback")
    proc.send_signal(sig)
    out, err = proc.communicate(timeout=60)
    assert "after callback" in out  # ctypes dropped the exception: the path under test ran
    assert proc.returncode == 143, (out, err)
    assert out.split()[-1] == ("Terminated" if sig == signal.SIGTERM else "KeyboardInterrupt")
    assert "Traceback" not in err, err
    assert target.read_text() == "before"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out.csv"]


def test_a_folder_of_outputs_is_never_replaced_over_the_users_files_or_an_input(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """``report --out`` over a demo folder whose log is the report's input, ``validate --plots``
    into a folder with the user's files or the input log: refused in one line, nothing changed."""
    from kinergy.cli import main

    demo = tmp_path / "d"
    with atomic_folder(demo) as folder:  # a folder kinergy wrote, with a log in it
        (folder / "logs").mkdir()
        assert (
            main(
                [
                    "simulate",
                    "ur5e",
                    "--trajectory",
                    "test-a",
                    "--out",
                    str(folder / "logs" / "a.csv"),
                ]
            )
            == 0
        )
    log = demo / "logs" / "a.csv"
    before = log.read_bytes()
    capsys.readouterr()
    assert main(["report", "ur5e", "--energy", str(log), "--out", str(demo)]) == 1
    err = capsys.readouterr().err
    assert f"--out {demo}: holds an input ({log})" in err and err.count("\n") == 1
    assert log.read_bytes() == before
    plots = tmp_path / "plots"
    plots.mkdir()
    (plots / "torque_errors.png").write_text("my plot")
    assert main(["validate", "ur5e", str(log), "--plots", str(plots)]) == 1
    err = capsys.readouterr().err
    assert "--plots" in err and "holds torque_errors.png, which kinergy did not write" in err
    assert (plots / "torque_errors.png").read_text() == "my plot"
    for inside in (demo / "logs", demo):
        assert main(["validate", "ur5e", str(log), "--plots", str(inside)]) == 1
        assert "--plots" in capsys.readouterr().err and log.read_bytes() == before
    assert main(["validate", "ur5e", str(log), "--plots", str(tmp_path / "new")]) == 0
    assert (tmp_path / "new" / "a_current.png").is_file() and (tmp_path / "new" / MARKER).is_file()
    assert main(["validate", "ur5e", str(log), "--plots", str(tmp_path / "new")]) == 0  # again


def test_an_existing_file_kinergy_did_not_write_is_never_replaced(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """``--out`` over a log or a user's file is refused in one line and the file kept; over a
    file kinergy wrote (its mark in the header, a PNG's Software text) it is replaced."""
    from kinergy.cli import main

    log = tmp_path / "a.csv"
    assert main(["simulate", "ur5e", "--trajectory", "test-a", "--out", str(log)]) == 0
    precious = tmp_path / "keep.toml"
    precious.write_text("precious = true\n")
    before = log.read_bytes()
    capsys.readouterr()
    for argv, words in (
        (["robot", "export", "ur5e", "--format", "urdf", "--out", str(log)], f"{log}: exists: kinergy never replaces a log"),
        (["simulate", "ur5e", "--trajectory", "test-b", "--out", str(log)], f"{log}: exists: kinergy never replaces a log, not even one it simulated"),
        (["robot", "export", "ur5e", "--format", "mjcf", "--out", str(precious)], f"{precious}: exists and kinergy did not write it"),
    ):  # fmt: skip
        assert main(argv) == 1
        err = capsys.readouterr().err
        assert f"--out: {words}" in err and err.count("\n") == 1
    assert log.read_bytes() == before and precious.read_text() == "precious = true\n"
    urdf = tmp_path / "ur5e.urdf"
    for _ in range(2):  # the second time over its own output
        assert main(["robot", "export", "ur5e", "--format", "urdf", "--out", str(urdf)]) == 0
    plot = tmp_path / "front.png"
    for _ in range(2):
        assert (
            main(["optimize", "ur5e", "test-a", "--pareto-points", "2", "--plot", str(plot)]) == 0
        )
    with pytest.raises(kinergy.KinergyError, match="exists and kinergy did not write it"):
        kinergy.identify([log], "ur5e", out=precious)
