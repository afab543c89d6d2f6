"""`kinergy demo` and `kinergy report`: the whole study on the twin, end to end."""

from __future__ import annotations

import re
import shutil
from html.parser import HTMLParser
from pathlib import Path

import pytest
from chromium import find_chromium, table_overflow

import kinergy
from kinergy.cli import main
from kinergy.cli.common import print_tables
from kinergy.cli.demo import TABLES
from kinergy.workflows.demo import nominal_drives, run_demo


class _Images(HTMLParser):
    def __init__(self) -> None:
        super().__init__()
        self.sources: list[str] = []

    def handle_starttag(self, tag: str, attrs: list[tuple[str, str | None]]) -> None:
        if tag == "img":
            self.sources += [v for k, v in attrs if k == "src" and v]


@pytest.fixture(scope="module")
def demo_run(tmp_path_factory: pytest.TempPathFactory):
    out = tmp_path_factory.mktemp("demo")
    return out, run_demo(out, mismatch="none")  # the twin is the UR5e doc's model


def test_demo_writes_a_report_whose_images_all_exist(demo_run) -> None:
    out, run = demo_run
    report = run.report
    assert report == out / "report.html" and report.exists()
    parser = _Images()
    parser.feed(report.read_text())
    # torque and current per test, box plots, power and breakdown per test, Pareto
    assert len(parser.sources) >= 11
    assert "figures/pareto.png" in parser.sources
    for src in parser.sources:
        assert (out / src).is_file() and (out / src).stat().st_size > 10_000, src
    assert sorted(p.name for p in (out / "logs").iterdir()) == ["test-a.csv", "test-b.csv"]


def test_demo_prints_the_five_tables_with_comparisons(demo_run) -> None:
    _out, run = demo_run
    tables = run.tables
    assert {"IV", "V", "VI", "VII", "VIII", "timing"} <= set(tables)
    program, _uniform, optimised = tables["timing"][0].rows
    assert float(optimised[2]) < float(program[2]) and optimised[-1] == "yes"
    assert "twin J_m (Table IV)" in tables["IV"][0].headers
    assert [t.caption[-6:] for t in tables["VII"]] == ["test A", "test B"]
    assert "R² (paper)" in tables["VII"][1].headers
    assert "E_elec (paper)" in tables["VIII"][0].headers


def test_demo_identifies_within_the_issue_tolerances(demo_run) -> None:
    # identification issue: rotor inertia 3 %, k_t 2 %, friction 10 % (or 0.005 N m)
    _out, run = demo_run
    tables = run.tables
    truth = kinergy.load_robot("ur5e")
    for j, row in enumerate(tables["IV"][0].rows):
        assert abs(float(row[-1])) < 3.0  # J_m + J_r error in %
        assert float(row[3]) == pytest.approx(truth.joints[j].drive.rotor_inertia, rel=0.03)
    (friction,) = tables["VI"]  # one friction model, the doc's: one table
    assert friction.headers == [
        "joint",
        "k_t [N m/A]",
        "viscous [N m s/rad]",
        "coulomb_direct [N m]",
        "coulomb_reverse [N m]",
        "smoothing [rad/s]",
        "standstill [rad/s]",
        "holding [1]",
    ]
    for j, row in enumerate(friction.rows):
        t = truth.joints[j].drive
        kt, kv, tdir, trev = (float(row[k].split()[0]) for k in (1, 2, 3, 4))
        assert kt == pytest.approx(t.torque_constant, rel=0.02)
        assert kv == pytest.approx(t.friction.params["viscous"], rel=0.10)
        assert abs(tdir - t.friction.params["coulomb_direct"]) <= max(
            0.1 * t.friction.params["coulomb_direct"], 0.005
        )
        assert abs(trev - t.friction.params["coulomb_reverse"]) <= max(
            0.1 * t.friction.params["coulomb_reverse"], 0.005
        )
    r2 = [float(row[4]) for table in tables["VII"] for row in table.rows]  # tests A and B
    assert min(r2) >= 0.98


def test_demo_text_fits_120_characters(demo_run, capsys: pytest.CaptureFixture[str]) -> None:
    """``kinergy demo --mismatch none`` prints its tables in lines of at most 120 characters
    (what the command prints: :func:`print_tables` of these tables)."""
    _out, run = demo_run
    tables = run.tables
    print_tables(tables, TABLES)
    text = capsys.readouterr().out
    assert "UR5e Table VI" in text and "UR5e Table VIII" in text
    assert max(len(line) for line in text.splitlines()) <= 120


def test_demo_report_fits_1280_px(demo_run, tmp_path: Path) -> None:
    """In a 1280 px browser window every table of the demo's report fits its card."""
    _out, run = demo_run
    report = run.report
    assert table_overflow(find_chromium(), report, tmp_path) == []


def test_demo_starts_from_guessed_drives() -> None:
    guessed = nominal_drives(kinergy.load_robot("ur5e"))
    assert all(
        j.drive.motor_inertia == 0.0 and j.drive.torque_constant == 0.1 for j in guessed.joints
    )


def test_cli_demo_and_report(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "demo"
    assert main(["demo", "--out", str(out)]) == 0
    text = capsys.readouterr().out
    for caption in (
        "UR5e Table IV",
        "UR5e Table V",
        "UR5e Table VI",
        "UR5e Table VII",
        "UR5e Table VIII",
    ):
        assert caption in text
    assert re.search(r"report: .*report\.html \(\d+\.\d s\)", text)
    # every line but the report's path (which names the user's folder) fits 120 characters
    assert max(len(line) for line in text.splitlines() if "report: " not in line) <= 120
    # friction per model: the realistic twin's joints get power-law models, one table each
    for caption in re.findall(r"^Friction and torque constants.*$", text, re.M):
        assert caption.endswith("power_law friction")
    # the default twin is not the model: truth against identified, an honest held-out R^2
    assert "The twin is not the model: truth against identified" in text
    assert "The held-out current R² is below 1 because" in text
    truth_rows = text.split("truth against identified")[1].splitlines()[2:8]
    held_out_r2 = [float(row.split()[-1]) for row in truth_rows]
    assert all(0.9 < r2 < 1.0 for r2 in held_out_r2)
    assert "The twin is not the model" in (out / "report.html").read_text()
    if shutil.which("chromium"):  # the report fits a 1280 px window (skipped without a browser)
        assert table_overflow(find_chromium(), out / "report.html", tmp_path / "browser") == []
    model = tmp_path / "id.toml"
    logs = out / "logs"
    assert main(["identify", str(logs / "test-a.csv"), "--robot", "ur5e", "--out", str(model)]) == 0
    capsys.readouterr()
    rep = tmp_path / "rep"
    assert (
        main(
            [
                "report",
                str(model),
                "--validate",
                str(logs / "test-b.csv"),
                "--energy",
                str(logs / "test-b.csv"),
                "--out",
                str(rep),
            ]
        )
        == 0
    )
    assert (rep / "report.html").exists()
    assert "UR5e Table VII" in capsys.readouterr().out
    assert main(["report", str(model), "--out", str(rep)]) == 1
