"""The documentation site's pages say what the code does, and point nowhere outside the repository.

Relations checked: the friction page has a row for every model of the registry, naming each of its
parameters; the checks page a row for every check ``--accept`` takes; the log formats page every
field name a column spec or header may use; the example files on the pages (a robot file, a task
file, a fleet manifest) read without error and the robot example is the built-in ``ur5e``'s first
joint; no page, nor mkdocs.yml, points to a file outside the repository.
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest

from kinergy.errors import KinergyError
from kinergy.files import read_toml
from kinergy.fleet.manifest import read_manifest
from kinergy.friction.registry import MODELS
from kinergy.io.fields import FIELDS
from kinergy.io.task import load_task
from kinergy.logs.checks import Check
from kinergy.model.library import load_robot
from kinergy.model.toml import robot_from_dict, robot_to_dict

ROOT = Path(__file__).resolve().parents[1]
DOCS = ROOT / "docs"
PAGES = sorted(DOCS.rglob("*.md"))


def _page(name: str) -> str:
    return (DOCS / name).read_text(encoding="utf-8")


def _example(name: str, kind: str) -> str:
    """The TOML block after ``<!-- file: KIND ... -->`` on a page."""
    match = re.search(rf"<!-- file: {kind}\b.*?-->\s*```toml\n(.*?)```", _page(name), re.S)
    assert match is not None, f"{name}: no '{kind}' example"
    return match.group(1)


def _rows(text: str) -> dict[str, str]:
    """Table rows whose first cell is one backticked name: name -> the rest of the row."""
    return {m.group(1): m.group(2) for m in re.finditer(r"^\| `([\w.]+)` \|(.*)$", text, re.M)}


def _cells(row: str) -> list[str]:
    """A table row's cells; a ``|`` inside a code span (``|wm|``) does not split them."""
    cells, current, code = [], "", False
    for char in row:
        if char == "`":
            code = not code
        if char == "|" and not code:
            cells.append(current)
            current = ""
        else:
            current += char
    return [*cells, current]


def _names(cell: str) -> set[str]:
    """Identifiers in a table cell, ``gamma1..gamma6`` expanded."""
    out = set(re.findall(r"[A-Za-z_]\w*", cell))
    for stem, first, last in re.findall(r"([a-z_]+)(\d)\.\.[a-z_]+(\d)", cell):
        out |= {f"{stem}{k}" for k in range(int(first), int(last) + 1)}
    return out


@pytest.mark.parametrize("model", sorted(MODELS))
def test_the_friction_page_names_every_model_and_its_parameters(model: str) -> None:
    rows = _rows(_page("FRICTION.md"))
    assert model in rows, f"docs/FRICTION.md has no row for the friction model {model!r}"
    named = _names(_cells(rows[model])[1])  # after the name: the torque, then the parameters
    missing = set(MODELS[model].parameters) - named
    assert not missing, f"docs/FRICTION.md, {model}: parameters not named {sorted(missing)}"


def test_the_checks_page_names_every_check() -> None:
    rows = _rows(_page("concepts/checks.md"))
    assert {c.value for c in Check} <= set(rows), sorted({c.value for c in Check} - set(rows))


def test_the_log_formats_page_names_every_field() -> None:
    text = _page("LOGFORMATS.md")
    missing = [name for name in FIELDS if f"`{name}`" not in text]
    assert not missing, f"docs/LOGFORMATS.md does not name the fields {missing}"


def test_the_robot_file_example_is_the_built_in_ur5e(tmp_path: Path) -> None:
    path = tmp_path / "robot.toml"
    path.write_text(_example("concepts/robot-file.md", "robot"), encoding="utf-8")
    example = robot_from_dict(read_toml(path, "robot file"))
    ur5e = robot_to_dict(load_robot("ur5e"))
    mine = robot_to_dict(example)
    assert mine["joints"] == ur5e["joints"][:1]
    for key in ("name", "description", "convention", "gravity", "standby_power", "bus_voltage"):
        assert mine[key] == ur5e[key], key
    assert mine["sources"]["kinematics"] == ur5e["sources"]["kinematics"]


def test_the_task_file_example_loads(tmp_path: Path) -> None:
    path = tmp_path / "task.toml"
    path.write_text(_example("files.md", "task"), encoding="utf-8")
    task = load_task(path, robot=load_robot("ur5e"))
    assert np.degrees(task.moves[0].target).tolist() == pytest.approx([10, -80, 30, -90, 0, 0])


def test_the_fleet_manifest_example_reads(tmp_path: Path) -> None:
    path = tmp_path / "fleet.toml"
    path.write_text(_example("files.md", "manifest"), encoding="utf-8")
    manifest = read_manifest(path)
    (robot,) = manifest.robots
    assert robot.name == "cell-3" and robot.model == "ur5e"
    path.write_text(_example("files.md", "manifest") + 'colour = "red"\n', encoding="utf-8")
    with pytest.raises(KinergyError, match="colour"):
        read_manifest(path)


@pytest.mark.parametrize("path", [*PAGES, ROOT / "mkdocs.yml"], ids=lambda p: p.name)
def test_nothing_points_outside_the_repository(path: Path) -> None:
    text = path.read_text(encoding="utf-8")
    for pattern in (r"DESIGN\.md", r"\.\./shared", r"datasets/", r"/work/", r"/tmp/pytest"):
        assert not re.search(pattern, text), f"{path.name} points outside the repository: {pattern}"


def test_the_built_cli_page_has_whole_summaries_and_no_sentinel(tmp_path: Path) -> None:
    """The command-line reference as the site shows it (docs/hooks/cli_page.py): no click
    ``Sentinel.UNSET`` in the Default column, and every command's summary a whole sentence."""
    pytest.importorskip("mkdocs_click")
    import os
    import subprocess
    import sys

    site = tmp_path / "site"
    build = subprocess.run(
        [sys.executable, "-m", "mkdocs", "build", "--strict", "--quiet", "-d", str(site)],
        cwd=ROOT,
        env={**os.environ, "NO_MKDOCS_2_WARNING": "1"},
        capture_output=True,
        text=True,
    )
    assert build.returncode == 0, build.stderr
    page = (site / "cli" / "index.html").read_text(encoding="utf-8")
    assert "Sentinel" not in page
    summaries = re.findall(r'<li><em><a href="#kinergy[^"]*">[^<]+</a></em>: ([^<]*)</li>', page)
    assert len(summaries) >= 20
    cut = [s for s in summaries if not s.rstrip().endswith((".", ".)"))]
    assert not cut, cut
