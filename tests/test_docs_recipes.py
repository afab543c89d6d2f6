"""The recipes page's Python example (docs/recipes.md, "The same from Python") runs as printed on
the real UR10e logs, in a fresh interpreter (as a user runs it: what a test run imported before
cannot help it), from a folder laid out as the user's (the repository's own paths), and prints
what the commands give: the held-out current R^2 of ``kinergy validate`` and the supply energy of
``kinergy energy`` on the model ``kinergy identify`` wrote from the same logs (the page quotes
them). Skipped when the datasets are not beside the repository.
"""

from __future__ import annotations

import ast
import contextlib
import io
import json
import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

from kinergy.cli.app import main

ROOT = Path(__file__).resolve().parents[1]
PAGE = ROOT / "docs" / "recipes.md"
UR10E = ROOT.parent / "shared" / "datasets" / "ur10e-innopolis"
RUNS = ("ur-20_02_19_15harm50sec", "ur-20_02_19_14harm50sec", "ur-20_02_12-50sec_12harm")
COLUMNS = "timestamp,actual_q:6,actual_qd:6,actual_current:6,target_current:6,target_moment:6"


def _python_recipe() -> str:
    text = PAGE.read_text(encoding="utf-8")
    match = re.search(
        r"<!-- recipe: tests/test_docs_recipes.py.*?-->\s*```python\n(.*?)```", text, re.S
    )
    assert match is not None, "the recipe block is gone from docs/recipes.md"
    return match.group(1)


def _json(argv: list[str]) -> dict:
    buffer = io.StringIO()
    with contextlib.redirect_stdout(buffer):
        assert main(argv) == 0
    return json.loads(buffer.getvalue())


@pytest.mark.skipif(not UR10E.exists(), reason="shared datasets not available")
def test_the_python_recipe_runs_and_matches_the_commands(tmp_path: Path) -> None:
    (tmp_path / "dynamic_calibration").mkdir()
    (tmp_path / "dynamic_calibration" / "dataset_ur10e").symlink_to(UR10E)
    (tmp_path / "recipe.py").write_text(_python_recipe(), encoding="utf-8")
    env = {
        **os.environ,
        "PYTHONPATH": os.pathsep.join([str(ROOT), os.environ.get("PYTHONPATH", "")]),
    }
    run = subprocess.run(
        [sys.executable, "recipe.py"], cwd=tmp_path, env=env, capture_output=True, text=True
    )
    assert run.returncode == 0, run.stderr
    printed = dict(line.split(": ", 1) for line in run.stdout.splitlines() if ": " in line)
    r2 = ast.literal_eval(printed["held-out current R²"])
    drawn = float(printed["drawn from the supply"].removesuffix(" J"))
    held_out = str(UR10E / "validation_data" / "ur-20_01_17-ptp_10_points.csv")
    runs = [str(UR10E / "identification_data" / f"{name}.csv") for name in RUNS]
    model = str(tmp_path / "cli.toml")
    _json(["identify", *runs, "--robot", "ur10e", "--columns", COLUMNS, "--out", model, "--json"])
    validated = _json(["validate", model, held_out, "--columns", COLUMNS, "--json"])
    energy = _json(["energy", model, held_out, "--columns", COLUMNS, "--json"])
    assert r2 == [round(m["r2"], 3) for m in validated["current"]]
    assert drawn == round(energy["supply"]["drawn"], 1)
    # the figures the page quotes for this recipe
    assert r2 == [0.963, 0.996, 0.997, 0.977, 0.96, 0.826]
    assert drawn == 3077.1
    assert (tmp_path / "ur10e-id.toml").exists() and (tmp_path / "ur10e-copy.toml").exists()
