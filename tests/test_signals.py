"""Killing a command at a random moment (issue 15): SIGTERM or SIGINT at a seeded random delay
into ``identify``, ``simulate``, ``optimize`` and ``report`` leaves no temporary file, and every
file that was there before is byte-identical (an output the command finished before the signal
may have been replaced, whole).

The commands run as real processes, all at once, so the test takes about as long as the slowest.
"""

from __future__ import annotations

import os
import random
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
from clicase import snapshot

from kinergy import load_robot
from kinergy.cli import main
from kinergy.errors import KinergyError
from kinergy.files import MARKER, _manifest
from kinergy.io.rtde import read_log

#: the child restores Python's Ctrl-C handler: a shell's background job starts with SIGINT ignored
_RUN = (
    "import signal, sys; signal.signal(signal.SIGINT, signal.default_int_handler); "
    "from kinergy.cli import run; sys.argv[0] = 'kinergy'; run()"
)

#: command -> (arguments, its declared outputs)
COMMANDS = {
    "identify": (["identify", "log.csv", "--robot", "ur5e", "--out", "model.toml"], ["model.toml"]),
    "simulate": (["simulate", "ur5e", "--trajectory", "test-b", "--out", "out.csv"], ["out.csv"]),
    "optimize": (
        ["optimize", "ur5e", "test-a", "--pareto-points", "3", "--urscript", "o.script"],
        ["o.script"],
    ),
    "report": (
        ["report", "ur5e", "--validate", "log.csv", "--energy", "log.csv", "--out", "rep"],
        ["rep"],
    ),
}


@pytest.fixture(scope="module")
def log_text(tmp_path_factory: pytest.TempPathFactory) -> bytes:
    folder = tmp_path_factory.mktemp("twin")
    assert main(["simulate", "ur5e", "--trajectory", "test-a", "--out", str(folder / "a.csv")]) == 0
    return (folder / "a.csv").read_bytes()


def _leftovers(folder: Path) -> list[str]:
    """Temporaries of kinergy.files: ``.NAME.*.tmp`` files and ``.NAME.*`` folders."""
    names = [p for p in snapshot(folder) if Path(p).name.startswith(".")]
    return sorted(p for p in names if Path(p).name != MARKER)


def test_killing_a_command_leaves_no_temporary_and_every_file_as_it_was(
    tmp_path: Path, log_text: bytes
) -> None:
    rng = random.Random(15)
    runs = []
    for name, (args, outputs) in COMMANDS.items():
        for sig in (signal.SIGTERM, signal.SIGINT):
            folder = tmp_path / f"{name}-{sig.name}"
            folder.mkdir()
            (folder / "log.csv").write_bytes(log_text)
            for out in outputs:  # an old output that must survive unless replaced whole
                if name == "report":
                    (folder / out).mkdir()
                    (folder / out / "report.html").write_text("old report\n")
                    (folder / out / MARKER).write_text(_manifest(folder / out))
                else:
                    (folder / out).write_text("old output\n")
            before = snapshot(folder)
            proc = subprocess.Popen(
                [sys.executable, "-c", _RUN, *args],
                cwd=folder,
                stdout=subprocess.DEVNULL,
                stderr=subprocess.PIPE,
                env={**os.environ, "PYTHONPATH": os.pathsep.join(sys.path)},
            )
            delay = rng.uniform(1.5, 6.0)  # the import takes ~1 s; each run a few seconds
            runs.append((name, sig, folder, outputs, before, proc, time.monotonic() + delay))
    for *_, proc, when in sorted(runs, key=lambda r: r[-1]):
        time.sleep(max(0.0, when - time.monotonic()))
        if proc.poll() is None:
            proc.send_signal(_sig_of(runs, proc))
    killed = 0
    for name, sig, folder, outputs, before, proc, _ in runs:
        proc.wait(timeout=60)
        assert proc.stderr is not None
        err = proc.stderr.read().decode(errors="replace")
        where = f"{name} {sig.name} (exit {proc.returncode})"
        assert "Traceback" not in err or proc.returncode == -sig, f"{where}: {err[-2000:]}"
        assert _leftovers(folder) == [], f"{where}: {_leftovers(folder)}"
        after = snapshot(folder)
        finished = proc.returncode == 0
        killed += not finished
        # A signal that lands after the last rename but before the process exits kills a run
        # whose outputs are already written whole: a changed output must then be complete.
        complete = finished or _complete(name, folder)
        for path, digest in before.items():
            replaced = complete and any(path.startswith(o) for o in outputs)
            if not replaced:
                assert after.get(path) == digest, f"{where}: {path} changed"
    assert killed >= len(runs) // 2, "most runs should be interrupted, not finish first"


def _complete(name: str, folder: Path) -> bool:
    """Whether ``name``'s output in ``folder`` is a whole new output (never a partial one)."""
    try:
        if name == "simulate":
            return len(read_log(folder / "out.csv").t) > 1000
        if name == "identify":
            return load_robot(folder / "model.toml").n == 6
        if name == "optimize":
            return (folder / "o.script").read_text().rstrip().endswith("end")
        return (folder / "rep" / "report.html").read_text().rstrip().endswith("</html>")
    except (KinergyError, OSError):
        return False


def _sig_of(runs: list[tuple], proc: subprocess.Popen[bytes]) -> int:
    return next(r[1] for r in runs if r[5] is proc)
