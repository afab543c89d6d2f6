"""``kinergy fleet energy`` on a twin fleet, on a local Dask cluster.

The fleet: three UR5e twins, seven days, one 6 s log a day of a 2.9 s program; robot-02's
friction rises 30 % over the week, robot-03 takes a 5 kg payload from the fourth day. Relations
checked: the drift flag names robot-02 and no other, robot-03's payload is a step change on its
day and not drift; the Parquet table has one row per cycle whose energies add up to each robot's
total and whose model parts add up to the prediction; an unworn robot's measured energy equals
the model's; per-cycle energies are the supply integral over the cycle; no cycle crosses a gap
in a log; LOGS and the globs name each log once; a user's scheduler gives the same answer as
the local cluster; every user error is one line and exit 1. The drift rule on synthetic series:
noise is not drift (and rarely a change), a ramp is drift, a step is a change, a step then a ramp both.
"""

from __future__ import annotations

import contextlib
import datetime as dt
import io
import json
import os
from pathlib import Path

import numpy as np
import pyarrow.parquet as pq
import pytest
from scipy.integrate import trapezoid

from kinergy.cli.app import main
from kinergy.fleet.analysis import analyse_log
from kinergy.fleet.drift import trend
from kinergy.fleet.manifest import FleetLog, fleet_logs, log_date, read_manifest
from kinergy.fleet.parquet import COLUMNS
from kinergy.fleet.twin import twin_fleet
from kinergy.io.rtde import read_log, write_log

DAYS = 7


@pytest.fixture(scope="module")
def fleet_dir(tmp_path_factory) -> Path:
    folder = tmp_path_factory.mktemp("fleet")
    twin_fleet(
        folder, robots=3, days=DAYS, logs=DAYS, seconds=6.0, programs=["short"],
        wear={"robot-02": 0.30}, payload={"robot-03": (3, 5.0)}, seed=1,
    )  # fmt: skip
    return folder


@pytest.fixture(scope="module")
def result(fleet_dir, tmp_path_factory):
    """The command's JSON and Parquet file (run once for the module, on two workers)."""
    out = tmp_path_factory.mktemp("out")
    argv = [
        "fleet", "energy", "--manifest", str(fleet_dir / "fleet.toml"),
        "--out", str(out / "fleet.parquet"), "--workers", "2", "--json",
    ]  # fmt: skip
    buffer = io.StringIO()
    with contextlib.redirect_stdout(buffer):
        assert main(argv) == 0
    return json.loads(buffer.getvalue()), out / "fleet.parquet"


def robots(data):
    return {r["name"]: r for r in data["robots"]}


def test_json_shape(result):
    data, _ = result
    assert data["logs"] == 3 * DAYS and data["workers"] == 2 and data["skipped"] == []
    for r in data["robots"]:
        assert {"name", "logs", "energy_J", "drift"} <= set(r)
        assert r["logs"] == DAYS and isinstance(r["drift"], bool)
        assert len(r["days"]) == DAYS


def test_drift_flags_the_worn_robot_only(result):
    data, _ = result
    by = robots(data)
    assert [name for name, r in by.items() if r["drift"]] == ["robot-02"]
    worn = by["robot-02"]["programs"][0]
    assert worn["friction_drift"] and 0.2 < worn["friction_rise"] < 0.4
    assert by["robot-02"]["changes"] == []
    changes = by["robot-03"]["changes"]
    assert changes and {c["date"] for c in changes} == {"2024-05-09"}
    assert all(c["relative"] > 0.02 for c in changes if c["metric"] == "energy")
    assert by["robot-01"]["changes"] == []


def test_parquet_rows_add_up(result):
    data, path = result
    table = pq.read_table(path).to_pandas()
    assert tuple(table.columns) == COLUMNS
    by = robots(data)
    for name, rows in table.groupby("robot"):
        assert rows["measured"].sum() == pytest.approx(by[name]["energy_J"], rel=1e-9)
        assert rows["predicted"].sum() == pytest.approx(by[name]["predicted_J"], rel=1e-9)
        assert len(rows[rows["cycle"] >= 0]) == by[name]["cycles"]
    parts = table[["inertial", "gravity", "friction", "copper", "standby", "shunt"]].sum(axis=1)
    np.testing.assert_allclose(parts, table["predicted"], rtol=1e-9, atol=1e-9)
    unworn = table[table["robot"] == "robot-01"]
    np.testing.assert_allclose(unworn["predicted"], unworn["measured"], rtol=0.02)
    assert set(table["program"]) == {"P1"}
    period = by["robot-01"]["programs"][0]["period"]
    assert np.allclose(table["duration"], period, atol=1e-9)


def test_cycle_energy_is_the_supply_integral(fleet_dir):
    item = fleet_logs(read_manifest(fleet_dir / "fleet.toml"))[0]
    result = analyse_log(item)
    log = read_log(item.path)
    power = log["actual_robot_voltage"] * log["actual_robot_current"]
    for c in result.cycles:
        fine = np.linspace(c.start, c.start + c.duration, 4001)
        expected = trapezoid(np.interp(fine, log.t, power), fine)
        assert c.measured == pytest.approx(expected, rel=2e-3)


def test_no_cycle_crosses_a_gap(fleet_dir, tmp_path):
    item = fleet_logs(read_manifest(fleet_dir / "fleet.toml"))[0]
    log = read_log(item.path)
    keep = np.r_[0:2000, 2600 : len(log)]
    signals = {k: v[keep] for k, v in log.signals.items()}
    signals["segment"] = (keep >= 2600).astype(float)
    path = tmp_path / "gap_2024-05-06.csv"
    write_log(path, log.t[keep], signals)
    result = analyse_log(FleetLog("robot-01", "ur5e", str(path), dt.date(2024, 5, 6)))
    assert {c.segment for c in result.cycles} == {0, 1}
    gap = (log.t[1999], log.t[2600])
    for c in result.cycles:
        assert c.start + c.duration <= gap[0] + 1e-9 or c.start >= gap[1] - 1e-9


def test_logs_and_globs_name_each_log_once(fleet_dir):
    manifest = read_manifest(fleet_dir / "fleet.toml")
    every = fleet_logs(manifest)
    again = fleet_logs(manifest, [every[0].path, every[5].path])
    assert [i.path for i in again] == [i.path for i in every]
    assert len({i.path for i in every}) == 3 * DAYS


def test_dates(tmp_path):
    named = tmp_path / "cell_2023-02-28_run.csv"
    named.write_text("x")
    assert log_date(named) == dt.date(2023, 2, 28)
    plain = tmp_path / "run.csv"
    plain.write_text("x")
    stamp = dt.datetime(2022, 7, 14, 12, 0).timestamp()
    os.utime(plain, (stamp, stamp))
    assert log_date(plain) == dt.date(2022, 7, 14)


def test_users_scheduler_same_answer(result, fleet_dir, tmp_path, capsys):
    from distributed import LocalCluster

    data, _ = result
    one = fleet_dir / "one.toml"  # robot-01 alone: the same figures for it
    one.write_text('[[robot]]\nname = "robot-01"\nmodel = "ur5e"\nlogs = "robot-01/*.csv"\n')
    with LocalCluster(n_workers=1, threads_per_worker=1, dashboard_address=None) as cluster:
        argv = [
            "fleet", "energy", "--manifest", str(one),
            "--out", str(tmp_path / "f.parquet"), "--scheduler", cluster.scheduler_address, "--json",
        ]  # fmt: skip
        assert main(argv) == 0
    again = json.loads(capsys.readouterr().out)
    assert again["workers"] == 1 and [r["name"] for r in again["robots"]] == ["robot-01"]
    first = robots(data)["robot-01"]
    assert again["robots"][0]["energy_J"] == pytest.approx(first["energy_J"], rel=1e-12)
    assert again["robots"][0]["drift"] == first["drift"]


def _write(path: Path, text: str) -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(text)
    return path


@pytest.mark.parametrize(
    ("manifest", "extra", "message"),
    [
        ("[[robot]]\nname = 'a'\nmodel = 'ur5e'\n", [], "'logs' must be a glob"),
        ("[[robot]]\nname = 'a'\nmodel = 'ur5e'\nlogs = 'none/*.csv'\n", [], "matches no file"),
        ("robot = 3\n", [], "no [[robot]] table"),
        ("[[robot\n", [], "not valid TOML"),
        ("[[robot]]\nname = 'a'\nmodel = 'ur5e'\nlogs = 'a/*.csv'\nspeed = 1\n", [], "unknown key(s) speed"),
        ("[[robot]]\nname = 'a'\nmodel = 'ur5e'\nlogs = 'a/*.csv'\n[[robot]]\nname = 'a'\nmodel = 'ur5e'\nlogs = 'a/*.csv'\n", [], "given twice"),
        ("[[robot]]\nname = 'a'\nmodel = 'nope'\nlogs = 'a/*.csv'\n", [], "nope"),
        ("[[robot]]\nname = 'a'\nmodel = 'ur5e'\nlogs = 'a/*.csv'\n", ["other/b.csv"], "belongs to no robot"),
        ("[[robot]]\nname = 'a'\nmodel = 'ur5e'\nlogs = 'a/*.csv'\n", ["missing.csv"], "no such log file"),
    ],
)  # fmt: skip
def test_manifest_errors_one_line(tmp_path, capsys, manifest, extra, message):
    _write(tmp_path / "a" / "a_2024-01-01.csv", "timestamp x\n0 1\n1 2\n")
    _write(tmp_path / "other" / "b.csv", "timestamp x\n0 1\n1 2\n")
    path = _write(tmp_path / "fleet.toml", manifest)
    argv = ["fleet", "energy", *(str(tmp_path / e) for e in extra), "--manifest", str(path)]
    assert main([*argv, "--out", str(tmp_path / "f.parquet")]) == 1
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and message in err, err
    assert not (tmp_path / "f.parquet").exists()


def test_output_equal_to_an_input(fleet_dir, capsys):
    log = next((fleet_dir / "robot-01").glob("*.csv"))
    before = log.read_bytes()
    argv = ["fleet", "energy", "--manifest", str(fleet_dir / "fleet.toml"), "--out", str(log)]
    assert main(argv) == 1
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "is also an input" in err
    assert log.read_bytes() == before


def test_unreachable_scheduler(fleet_dir, tmp_path, capsys):
    argv = [
        "fleet", "energy", "--manifest", str(fleet_dir / "fleet.toml"),
        "--out", str(tmp_path / "f.parquet"), "--scheduler", "tcp://127.0.0.1:9",
    ]  # fmt: skip
    assert main(argv) == 1
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "--scheduler tcp://127.0.0.1:9: cannot reach it" in err


# -- the drift rule on synthetic series ---------------------------------------------------------


def series(levels, seed=0, noise=0.004, cycles=4):
    rng = np.random.default_rng(seed)
    days = [dt.date(2024, 1, 1) + dt.timedelta(days=k) for k in range(len(levels))]
    day_noise = 1.0 + noise * rng.standard_normal(len(levels))
    values = [
        lv * d * (1 + 0.0005 * rng.standard_normal(cycles))
        for lv, d in zip(levels, day_noise, strict=True)
    ]
    return days, values


def test_noise_is_not_drift_and_rarely_a_change():
    trends = [trend(*series([100.0] * 7, seed=seed)) for seed in range(300)]
    assert not any(tr.drift for tr in trends)
    assert sum(bool(tr.changes) for tr in trends) <= 3  # measured: 1 in 300


@pytest.mark.parametrize("seed", range(10))
def test_ramp_is_drift(seed):
    tr = trend(*series(100.0 * (1 + 0.3 * np.arange(7) / 6), seed=seed))
    assert tr.drift and tr.changes == [] and 0.25 < tr.rise < 0.35


@pytest.mark.parametrize("seed", range(10))
@pytest.mark.parametrize("jump", [0.05, 0.10])
def test_step_is_a_change(seed, jump):
    tr = trend(*series([100.0] * 3 + [100.0 + 100 * jump] * 4, seed=seed))
    assert not tr.drift and [c.date.day for c in tr.changes] == [4]
    assert tr.changes[0].relative == pytest.approx(jump, abs=0.02)


def test_step_then_ramp():
    levels = [100.0] * 4 + list(120.0 * (1 + 0.25 * np.arange(6) / 5))
    tr = trend(*series(levels, seed=3))
    assert tr.drift and [c.date.day for c in tr.changes] == [5]


def test_the_api_gives_the_command_s_json(result, fleet_dir, tmp_path):
    """``kinergy.api.fleet_energy``'s ``to_dict()`` is the command's ``--json`` but for the run's
    own wall time and memory."""
    import kinergy.api as api

    data, _ = result
    run = api.fleet_energy(
        [], fleet_dir / "fleet.toml", tmp_path / "fleet.parquet", api.FleetOptions(workers=2)
    )
    got = json.loads(json.dumps(run.to_dict()))
    cli = {k: v for k, v in data.items() if k not in ("kinergy", "inputs")}
    for out in (got, cli):
        out.pop("seconds"), out.pop("peak_rss_MB")
    assert got == cli
