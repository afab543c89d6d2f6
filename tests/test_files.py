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
    target.write_text("old")

    def fail(fh: object) -> None:
        raise RuntimeError("boom")

    with pytest.raises(RuntimeError):
        atomic_write(target, fail)
    assert target.read_text() == "old"
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
    with pytest.raises(KinergyError, match="holds files kinergy did not write"):
        with atomic_folder(mine):
            pass
    assert (mine / "thesis.tex").read_text() == "precious"


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
