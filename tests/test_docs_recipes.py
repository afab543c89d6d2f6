"""The recipes page's Python example (docs/recipes.md, "The same from Python") runs as printed on
the real UR10e logs, from a folder laid out as the user's (the repository's own paths), and gives
what the commands give: the held-out current R^2 of ``kinergy validate`` and the supply energy of
``kinergy energy`` on the model ``kinergy identify`` wrote from the same logs (the page quotes
them). Skipped when the datasets are not beside the repository.
"""

from __future__ import annotations

import contextlib
import io
import json
import re
import runpy
from pathlib import Path

import pytest

from kinergy.cli.app import main

ROOT = Path(__file__).resolve().parents[1]
PAGE = ROOT / "docs" / "recipes.md"
UR10E = ROOT.parent / "shared" / "datasets" / "ur10e-innopolis"
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
@pytest.mark.xfail(
    strict=True,
    raises=TypeError,
    reason="kinergy.identify is the sub-package kinergy.identify once kinergy.api is imported "
    "(kinergy.read_log imports it): Python binds a sub-package to its parent's attribute, "
    "shadowing the public function of the same name (kinergy.simulate likewise); remove this "
    "mark when kinergy/__init__.py keeps the functions",
)
def test_the_python_recipe_runs_and_matches_the_commands(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    (tmp_path / "dynamic_calibration").mkdir()
    (tmp_path / "dynamic_calibration" / "dataset_ur10e").symlink_to(UR10E)
    (tmp_path / "recipe.py").write_text(_python_recipe(), encoding="utf-8")
    monkeypatch.chdir(tmp_path)
    ns = runpy.run_path("recipe.py")
    held_out = ns["held_out"]
    argv = ["identify", *ns["runs"], "--robot", "ur10e", "--columns", COLUMNS]
    _json([*argv, "--out", "cli.toml", "--json"])
    validated = _json(["validate", "cli.toml", held_out, "--columns", COLUMNS, "--json"])
    energy = _json(["energy", "cli.toml", held_out, "--columns", COLUMNS, "--json"])
    r2 = [m.r2 for m in ns["report"].current]
    assert r2 == pytest.approx([m["r2"] for m in validated["current"]], rel=1e-9)
    assert ns["energy"].supply.drawn == pytest.approx(energy["supply"]["drawn"], rel=1e-9)
    # the figures the page quotes for this recipe
    assert [round(x, 3) for x in r2] == [0.963, 0.996, 0.997, 0.977, 0.96, 0.826]
    assert round(ns["energy"].supply.drawn, 1) == 1111.8
