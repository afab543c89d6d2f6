"""The layers contract (pyproject.toml, docs/ARCHITECTURE.md) holds, and a back-edge breaks it;
so does the front door's (a command importing a workflow past the Python API).

The check runs import-linter on a copy of the package, so adding an upward import to the copy
cannot touch the real one.
"""

from __future__ import annotations

import shutil
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
LINT = shutil.which("lint-imports") or str(Path(sys.executable).parent / "lint-imports")


def _lint(tree: Path) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [LINT, "--config", str(tree / "pyproject.toml")],
        cwd=tree,
        capture_output=True,
        text=True,
        env={"PYTHONPATH": str(tree), "PATH": str(Path(sys.executable).parent)},
        timeout=120,
    )


@pytest.fixture(scope="module")
def copy(tmp_path_factory: pytest.TempPathFactory) -> Path:
    if not Path(LINT).exists():
        pytest.skip("import-linter not installed (pip install '.[test]')")
    tree = tmp_path_factory.mktemp("layers")
    shutil.copytree(
        ROOT / "kinergy", tree / "kinergy", ignore=shutil.ignore_patterns("__pycache__")
    )
    shutil.copy(ROOT / "pyproject.toml", tree / "pyproject.toml")
    return tree


def test_the_package_keeps_its_layers(copy: Path) -> None:
    result = _lint(copy)
    assert result.returncode == 0, result.stdout + result.stderr
    assert "2 kept, 0 broken" in result.stdout


@pytest.mark.parametrize(
    ("module", "upward"),
    [
        ("kinergy/dynamics/rnea.py", "kinergy.accounting.energy"),  # dynamics -> energy
        ("kinergy/model/robot.py", "kinergy.cli.app"),  # model -> cli
        ("kinergy/report/html.py", "kinergy.workflows.demo"),  # report -> workflows
        ("kinergy/cli/energy.py", "kinergy.workflows.energy"),  # a command past the API
    ],
)
def test_a_back_edge_breaks_the_contract(copy: Path, module: str, upward: str) -> None:
    target = copy / module
    original = target.read_text()
    try:
        target.write_text(original + f"\nimport {upward}  # a back-edge\n")
        result = _lint(copy)
    finally:
        target.write_text(original)
    assert result.returncode != 0
    assert "BROKEN" in result.stdout and upward in result.stdout
