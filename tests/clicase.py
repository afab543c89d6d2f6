"""Running one command line as a careless or hostile user would, and checking what it left.

:func:`run_case` runs ``kinergy ARGS`` in-process (through :func:`kinergy.cli.main`, the entry
point that turns errors into one line) inside a folder and checks the promises of issue 15:

- no traceback: an exception escaping ``main`` fails the test with its traceback;
- a refusal (non-zero exit) is exactly one line on stderr, ``kinergy: error: ...``;
- no file in the folder changed, appeared or vanished except the declared outputs (and those
  only on success), no temporary left behind;
- it took under :data:`LIMIT` seconds;
- ``--json`` output, on success, is strict JSON (``null``, never ``NaN`` or ``Infinity``).

Used by the corpus (tests/test_corpus.py) and the fuzz suite (tests/test_fuzz_*.py).
"""

from __future__ import annotations

import contextlib
import hashlib
import io
import json
import os
import time
import warnings
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

from kinergy.cli import main

#: seconds a single case may take
LIMIT = 10.0


def snapshot(folder: Path) -> dict[str, str]:
    """Every file (hidden ones too) and folder under ``folder``: relative path -> content hash."""
    out = {}
    for root, dirs, files in os.walk(folder):
        for name in dirs:
            out[os.path.relpath(os.path.join(root, name), folder) + "/"] = "folder"
        for name in files:
            path = os.path.join(root, name)
            rel = os.path.relpath(path, folder)
            if os.path.islink(path) or not os.path.isfile(path):
                out[rel] = "special"
            else:
                with open(path, "rb") as fh:
                    out[rel] = hashlib.sha256(fh.read()).hexdigest()
    return out


def _strict_json(text: str) -> object:
    def refuse(name: str) -> object:
        raise AssertionError(f"--json printed a bare {name}")

    return json.loads(text, parse_constant=refuse)


@dataclass(frozen=True)
class Outcome:
    status: int
    out: str
    err: str
    seconds: float


def run_case(
    args: Sequence[str],
    folder: Path,
    *,
    outputs: Sequence[str] = (),
    refuse: bool | None = None,
) -> Outcome:
    """Run ``kinergy ARGS`` with the current folder ``folder`` and check the promises above.

    Parameters
    ----------
    outputs : sequence of str
        Paths (relative to ``folder``) the command may write, and under which it may write.
    refuse : bool, optional
        True: the case must be refused; False: it must succeed; None: either.
    """
    before = snapshot(folder)
    out, err = io.StringIO(), io.StringIO()
    cwd = os.getcwd()
    start = time.perf_counter()
    try:
        os.chdir(folder)
        with (
            contextlib.redirect_stdout(out),
            contextlib.redirect_stderr(err),
            warnings.catch_warnings(record=True) as caught,
        ):
            warnings.simplefilter("always")
            status = main(list(args))
    finally:
        os.chdir(cwd)
    seconds = time.perf_counter() - start
    outcome = Outcome(status, out.getvalue(), err.getvalue(), seconds)
    where = f"kinergy {' '.join(args)!r:.300}"
    assert "Traceback" not in outcome.err, f"{where}: {outcome.err}"
    assert seconds < LIMIT, f"{where}: took {seconds:.1f} s"
    if refuse is not None:
        assert (status != 0) == refuse, f"{where}: exit {status}; {outcome.err or outcome.out:.500}"
    after = snapshot(folder)
    if status != 0:
        # a warning prints on the user's stderr (two lines) before the one line of the refusal
        shown = [f"{w.category.__name__}: {w.message} ({w.filename}:{w.lineno})" for w in caught]
        assert not shown, f"{where}: warnings before the refusal: {shown}"
        lines = outcome.err.splitlines()
        assert len(lines) == 1 and lines[0].startswith("kinergy: error: "), f"{where}: {lines}"
        assert after == before, f"{where}: files changed on a refusal: {_diff(before, after)}"
    else:
        changed = _diff(before, after)
        stray = [p for p in changed if not any(_under(p, o) for o in outputs)]
        assert not stray, f"{where}: wrote outside its declared outputs: {stray}"
        if "--json" in args:
            _strict_json(outcome.out)
    return outcome


def _under(path: str, output: str) -> bool:
    path, output = path.rstrip("/"), output.rstrip("/")
    return path == output or path.startswith(output + "/")


def _diff(before: dict[str, str], after: dict[str, str]) -> list[str]:
    keys = set(before) | set(after)
    return sorted(k for k in keys if before.get(k) != after.get(k))
