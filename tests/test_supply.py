"""The arm's supply: the bus model (motors shared on the DC bus, surplus to the shunt, standing
draw), the measured supply energy of a log beside the predicted one, and each joint's logged bus
voltage."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

import kinergy
from kinergy.accounting.supply import measured_supply, supply_energy
from kinergy.accounting.trace import PowerSeries, TraceWriter, trace_columns
from kinergy.cli import main
from kinergy.drives.bus import BUS_RESISTANCE, supply_power
from kinergy.io.rtde import write_log
from kinergy.predict import drive_state
from kinergy.trajectory.programs import paper_trajectory
from kinergy.twin import TwinSettings, simulate
from kinergy.workflows.energy import energy_of_log


def test_joints_share_the_bus_and_the_surplus_goes_to_the_shunt() -> None:
    power = np.array([[100.0, -30.0], [20.0, -50.0], [-10.0, -5.0]])
    bus = supply_power(power, standby=12.0)
    assert bus.bus.tolist() == [70.0, -30.0, -15.0]
    assert bus.motors.tolist() == [70.0, 0.0, 0.0]
    assert bus.shunt.tolist() == [0.0, 30.0, 15.0]
    assert bus.supply.tolist() == [82.0, 12.0, 12.0]


def test_supply_energy_of_constant_powers_is_closed_form() -> None:
    t = np.linspace(0.0, 10.0, 501)
    power = np.column_stack([np.full(t.size, 40.0), np.where(t < 5.0, 10.0, -60.0)])
    e = supply_energy(t, power, standby_power=20.0)
    assert e.standby == pytest.approx(200.0)
    # 50 W for 5 s, then -20 W (to the shunt) for 5 s; the step is one sample wide
    assert e.motors == pytest.approx(250.0, abs=2.0)
    assert e.shunt == pytest.approx(100.0, abs=2.0)
    assert e.drawn == pytest.approx(e.motors + e.standby)
    assert e.mean_power == pytest.approx(e.drawn / 10.0)
    assert "shunt" in e.includes and "standby" in e.includes
    m = measured_supply(t, np.full(t.size, 48.0), np.full(t.size, 2.0))
    assert m.drawn == pytest.approx(960.0) and m.mean_power == pytest.approx(96.0)
    assert "actual_robot_voltage" in m.includes


@pytest.fixture(scope="module")
def exact_log(tmp_path_factory: pytest.TempPathFactory, ur5e: kinergy.Robot) -> Path:
    path = tmp_path_factory.mktemp("supply") / "a.csv"
    # the model itself is the truth
    twin = simulate(ur5e, paper_trajectory(ur5e, "test-a", dt=0.004), TwinSettings.exact())
    write_log(path, twin.t, twin.signals)
    return path


def test_exact_twin_supply_is_predicted_exactly(ur5e: kinergy.Robot, exact_log: Path) -> None:
    report = energy_of_log(ur5e, exact_log)
    assert report.measured is not None
    assert report.supply.drawn == pytest.approx(report.measured.drawn, rel=1e-6)
    # with braking surplus in the shunt the supply draws more than the signed bus integral
    assert report.supply.shunt > 0.0
    assert report.supply.motors == pytest.approx(
        report.total_e_elec + report.supply.shunt, rel=1e-6
    )
    out = report.to_dict()
    assert abs(out["measured"]["error"]) < 1e-4
    assert {"drawn", "motors", "standby", "shunt", "includes"} <= set(out["supply"])


def test_cli_energy_prints_predicted_against_measured(
    ur5e: kinergy.Robot, exact_log: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    assert main(["energy", "ur5e", str(exact_log)]) == 0
    text = capsys.readouterr().out
    assert "Drawn from the arm's supply" in text and "Measured by the log" in text
    assert "predicted: " in text and "measured: " in text and "not the control box" in text
    # a log without supply columns: only the prediction, saying what it includes
    motion = tmp_path / "m.csv"
    twin = simulate(ur5e, paper_trajectory(ur5e, "test-b", dt=0.004), TwinSettings.exact())
    write_log(motion, twin.t, {k: twin[k] for k in ("target_q", "actual_q", "actual_qd")})
    assert main(["energy", "ur5e", str(motion), "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert "measured" not in out and out["supply"]["drawn"] > 0


def test_the_twin_logs_each_joints_bus_voltage_not_its_motors(ur5e: kinergy.Robot) -> None:
    """``actual_joint_voltage`` is each joint's supply, as a UR controller logs it: the supply
    voltage less the arm's cable drop, the same whatever the motor does (its own voltage swings
    with its speed and current)."""
    twin = simulate(ur5e, paper_trajectory(ur5e, "test-a", dt=0.004), TwinSettings.exact())
    joint, supply = twin["actual_joint_voltage"], twin["actual_robot_voltage"]
    drop = BUS_RESISTANCE * twin["actual_robot_current"]
    np.testing.assert_allclose(joint, (supply - drop)[:, None] * np.ones(6), rtol=1e-12)
    assert np.ptp(joint) < 2.0  # a volt or so of cable drop at the peak current
    motor = drive_state(ur5e, twin["actual_q"], twin["actual_qd"], twin["target_qdd"]).voltage
    assert np.ptp(motor) > 10.0  # what the twin used to write: swings with speed


def test_the_trace_streams_chunk_by_chunk_and_adds_up_to_the_figures(
    ur5e: kinergy.Robot, exact_log: Path, tmp_path: Path
) -> None:
    """A trace written 300 samples at a time is the trace written at once, row for row; its
    powers integrate to the report's supply energies, and each joint's to its E_elec."""
    traces = {}
    for rows in (300, 100_000):
        path = tmp_path / f"trace{rows}.parquet"
        with path.open("wb") as fh:
            writer = TraceWriter(fh, ur5e, "parquet")
            report = energy_of_log(ur5e, exact_log, rows=rows, sinks=[writer])
            writer.close()
        traces[rows] = pd.read_parquet(path)
    a, b = traces[300], traces[100_000]
    pd.testing.assert_frame_equal(a, b, rtol=1e-12)
    assert list(a.columns) == trace_columns(ur5e, measured=True)
    assert len(a) == report.samples
    t = a["time"].to_numpy()
    assert np.trapezoid(a["supply_predicted"], t) == pytest.approx(report.supply.drawn, rel=1e-9)
    assert report.measured is not None
    assert np.trapezoid(a["supply_measured"], t) == pytest.approx(report.measured.drawn, rel=1e-9)
    for j, name in enumerate(ur5e.joint_names):
        e = np.trapezoid(a[f"p_elec_{name}"], t)
        assert e == pytest.approx(report.e_elec[j], rel=1e-9)
    # the standing draw is in every sample of the supply
    motors = np.maximum(a[[f"p_elec_{n}" for n in ur5e.joint_names]].sum(axis=1), 0.0)
    np.testing.assert_allclose(a["supply_predicted"] - motors, ur5e.standby_power, atol=1e-9)


def test_a_plots_series_stays_bounded_and_keeps_every_kth_sample() -> None:
    series = PowerSeries(limit=1000)
    t = np.arange(25_000, dtype=float)
    for start in range(0, t.size, 1234):
        part = t[start : start + 1234]
        series.add(part, 2.0 * part, None, np.zeros((part.size, 6)))
    assert len(series.t) <= 1000 and series.measured is None
    step = series.stride
    np.testing.assert_array_equal(series.t, t[::step])
    np.testing.assert_array_equal(series.predicted, 2.0 * t[::step])


def test_cli_trace_and_plot(
    exact_log: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    trace, plot = tmp_path / "t.csv", tmp_path / "p.png"
    argv = ["energy", "ur5e", str(exact_log)]
    assert main([*argv, "--trace", str(trace), "--plot", str(plot)]) == 0
    assert pd.read_csv(trace).columns[2] == "supply_measured"
    assert plot.read_bytes()[:4] == b"\x89PNG"
    capsys.readouterr()
    # an extension that is neither: one line before any work, nothing written
    assert main([*argv, "--trace", str(tmp_path / "t.txt")]) == 1
    err = capsys.readouterr().err
    assert "--trace" in err and ".csv" in err and err.count("\n") == 1
    assert not (tmp_path / "t.txt").exists()
    # a file of the user's is never replaced
    mine = tmp_path / "mine.csv"
    mine.write_text("precious\n")
    assert main([*argv, "--trace", str(mine)]) == 1
    assert mine.read_text() == "precious\n"


def test_validate_compares_the_supply_where_the_log_measures_it(
    ur5e: kinergy.Robot, exact_log: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """On the exact twin the supply's power is the model's: RMSE 0, energy error 0; the figures
    are the independent numpy ones of the trace."""
    assert main(["validate", "ur5e", str(exact_log), "--json"]) == 0
    supply = json.loads(capsys.readouterr().out)["supply"]
    report = energy_of_log(ur5e, exact_log)
    assert report.measured is not None
    assert supply["rms"] < 1e-6 and abs(supply["error"]) < 1e-6
    assert supply["measured"] == pytest.approx(report.measured.drawn, rel=1e-9)
    assert main(["validate", "ur5e", str(exact_log)]) == 0
    assert "Supply power against actual_robot_voltage x actual_robot_current" in (
        capsys.readouterr().out
    )


def test_the_report_shows_the_supply_plot(exact_log: Path, tmp_path: Path) -> None:
    out = tmp_path / "report"
    assert main(["report", "ur5e", "--energy", str(exact_log), "--out", str(out)]) == 0
    figure = out / "figures" / "a-csv_supply.png"
    assert figure.read_bytes()[:4] == b"\x89PNG"
    html = (out / "report.html").read_text(encoding="utf-8")
    assert "figures/a-csv_supply.png" in html and "power drawn from the arm&#39;s supply" in html


@pytest.mark.parametrize("fmt", ["csv", "parquet"])
def test_a_traces_memory_does_not_grow_with_the_log(
    ur5e: kinergy.Robot, tmp_path: Path, fmt: str
) -> None:
    """Chunk after chunk, the writer and a plot's series hold what one chunk needs: the peak of
    numpy's and Python's memory (tracemalloc) and of Arrow's pool over 200 chunks of 5,000 rows
    (1,000,000 samples) is that of 20 chunks."""
    import tracemalloc

    import pyarrow as pa

    rng = np.random.default_rng(0)
    rows = 5_000
    chunk = [rng.standard_normal(rows) for _ in range(2)], rng.standard_normal((rows, 6))

    def peak(chunks: int) -> tuple[int, int]:
        arrow = 0
        tracemalloc.start()
        with (tmp_path / f"t{chunks}.{fmt}").open("wb") as fh:
            writer, series = TraceWriter(fh, ur5e, fmt), PowerSeries(limit=2_000)
            for k in range(chunks):
                t = np.arange(k * rows, (k + 1) * rows) * 0.002
                for sink in (writer, series):
                    sink.add(t, chunk[0][0], chunk[0][1], chunk[1])
                arrow = max(arrow, pa.total_allocated_bytes())
            writer.close()
        _, top = tracemalloc.get_traced_memory()
        tracemalloc.stop()
        return top, arrow

    short, long = peak(20), peak(200)
    assert long[0] < 1.2 * short[0] + 1_000_000
    assert long[1] < 1.2 * short[1] + 1_000_000
    assert (tmp_path / f"t200.{fmt}").stat().st_size > 5 * (tmp_path / f"t20.{fmt}").stat().st_size
