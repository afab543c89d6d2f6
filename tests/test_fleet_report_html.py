"""The fleet report: written from fleet results, parsed back, and opened in a real browser.

The results are made by hand (no simulation, no Dask): three robots over six days, robot-b's
friction and energy per cycle rising 30 %, robot-c's energy stepping up 10 % on the fourth day
(a new payload). Checked with the standard library's parser (tests/test_report_html.py's
``Page``): one section per robot after the overview, every image a file beside the report with
its true size and a caption, the overview names robot-b alone as drifting and robot-c's step as
a change; and in headless Chromium (skipped when absent) every image of the page decodes.
"""

from __future__ import annotations

import datetime as dt
from pathlib import Path
from urllib.parse import unquote

import pytest
from test_report_html import Page, chromium, image_states, png_size

from kinergy.fleet.analysis import CycleRecord, LogResult
from kinergy.fleet.manifest import FleetLog
from kinergy.fleet.summary import FleetResult, summarise
from kinergy.report.fleet import write_fleet_report

__all__ = ["chromium"]  # the browser fixture, shared with the study report's test

DAYS = 6
START = dt.date(2024, 5, 6)


def _log(robot: str, day: int, level: float, work: float) -> tuple[FleetLog, LogResult]:
    date = START + dt.timedelta(days=day)
    path = f"/logs/{robot}/{robot}_{date}.csv"
    wobble = [1.0, 1.001, 0.999, 1.0005]
    cycles = [
        CycleRecord(
            segment=0,
            cycle=k,
            start=3.0 * k,
            duration=3.0,
            measured=level * w,
            predicted=0.99 * level * w,
            inertial=0.2 * level,
            gravity=0.3 * level,
            friction=0.25 * level * w,
            copper=0.1 * level,
            standby=0.14 * level,
            shunt=0.0,
            motor_work=work * w,
        )
        for k, w in enumerate(wobble)
    ]
    ranges = [-1.0] * 6 + [1.0] * 6
    return FleetLog(robot, "ur5e", path, date), LogResult(
        robot, path, date, period=3.0, ranges=ranges, samples=6000, cycles=cycles, worker=1
    )


def fleet() -> FleetResult:
    noise = [1.0, 1.003, 0.998, 1.002, 0.997, 1.001]
    pairs = []
    for d in range(DAYS):
        wear = 1.0 + 0.3 * d / (DAYS - 1)
        pairs += [
            _log("robot-a", d, 95.0 * noise[d], 80.0 * noise[d]),
            _log("robot-b", d, 95.0 * wear * noise[d], 80.0 * wear * noise[d]),
            _log("robot-c", d, 95.0 * (1.1 if d >= 3 else 1.0) * noise[d], 80.0 * noise[d]),
        ]
    items, results = zip(*pairs, strict=True)
    return summarise(list(items), list(results), workers=2, seconds=1.5)


@pytest.fixture(scope="module")
def report(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return write_fleet_report(fleet(), tmp_path_factory.mktemp("fleet") / "report")


def test_the_results_behind_the_page() -> None:
    result = fleet()
    by = {r.name: r for r in result.robots}
    assert [r.name for r in result.robots if r.drift] == ["robot-b"]
    assert [(c.metric, str(c.date)) for c in by["robot-c"].changes] == [("energy", "2024-05-09")]


def test_sections_images_and_text(report: Path) -> None:
    page = Page(report.read_text(encoding="utf-8"))
    ids = [s["id"] for s in page.find("section")]
    assert ids == ["fleet", "robot-a", "robot-b", "robot-c"]
    images = page.find("img")
    assert len(images) == 1 + 3
    for img in images:
        file = report.parent / unquote(img["src"])
        assert file.is_file(), img["src"]
        assert (int(img["width"]), int(img["height"])) == png_size(file)
        assert img["alt"]
    assert len(page.captured["figcaption"]) == 4
    text = " ".join(page.text.split())
    assert "changes) : robot-b." not in text  # the sentence names robot-b alone
    assert "(energy or friction per cycle rising beyond its own spread): robot-b." in text
    assert "Step change of energy on 2024-05-09 in program P1" in text
    assert "a change, not drift" in text
    assert not page.find("script")


def test_browser_loads_every_image(chromium: str, report: Path, tmp_path: Path) -> None:
    states = image_states(chromium, report, tmp_path)
    srcs = [img["src"] for img in Page(report.read_text(encoding="utf-8")).find("img")]
    assert [s["src"] for s in states] == srcs and len(srcs) == 4
    for s in states:
        assert s["complete"], s
        assert s["width"] > 0, f"{s['src']} did not load"
        assert (s["width"], s["height"]) == png_size(report.parent / unquote(s["src"]))
