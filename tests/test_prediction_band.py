"""validate's 95 % prediction band (issue 36): the modes' shifts of the predicted currents and
reference torques against the model moved along each mode, the metrics' spread against brute
force, and what validate prints, writes and plots."""

from __future__ import annotations

import dataclasses
import json

import numpy as np
import pytest

import kinergy
from kinergy.identification.prediction_band import NO_BAND, BandTally, half_widths
from kinergy.identification.uncertainty import current_shifts, torque_shifts
from kinergy.identification.validation import validation_report
from kinergy.model.robot import transmission_matrix
from kinergy.model.toml import robot_from_dict, robot_to_dict
from kinergy.model.uncertainty import Uncertainty, parameter_value, perturbed, t_quantile
from kinergy.predict import drive_state
from kinergy.trajectory.programs import paper_trajectory


def _with_errors(robot: kinergy.Robot, seed: int = 0, rel: float = 0.03) -> kinergy.Robot:
    """``robot`` with made-up jackknife-like modes on every drive parameter, a calibration
    factor and identification residuals."""
    names = []
    for j, joint in enumerate(robot.joints):
        names += [f"joints[{j}].rotor_inertia", f"joints[{j}].torque_constant"]
        names += [f"joints[{j}].friction.{p}" for p in joint.drive.friction.model.linear]
    values = np.array([parameter_value(robot, n) for n in names])
    rng = np.random.default_rng(seed)
    modes = rng.normal(size=(10, len(names))) * rel * np.abs(values) / np.sqrt(10)
    residual = {"current": (0.05,) * robot.n, "torque": (0.5,) * robot.n}
    u = Uncertainty(tuple(names), modes, 9, "test modes", 1.3, residual)
    return dataclasses.replace(robot, uncertainty=u)


def _motion(robot: kinergy.Robot) -> kinergy.Motion:
    m = paper_trajectory(robot, "test-a", dt=0.01)
    return kinergy.Motion(t=m.t[:300], q=m.q[:300], qd=m.qd[:300], qdd=m.qdd[:300])


def test_current_and_torque_shifts_are_the_model_moved_along_each_mode(ur5e):
    """Each mode's shift of the predicted current and reference torque (times c) against the
    drive model recomputed with the parameters moved by a thousandth of that mode (a finite
    difference): to 0.5 % of the largest shift."""
    robot = _with_errors(ur5e)
    u = robot.uncertainty
    m = _motion(robot)
    state = drive_state(robot, m.q, m.qd, m.qdd)
    currents = current_shifts(robot, state)
    torques = torque_shifts(robot, m.qdd @ transmission_matrix(robot).T)
    for k in (0, 3):
        step = 1e-3 * u.calibration * u.modes[k]
        moved = perturbed(robot, dict(zip(u.parameters, step, strict=True)))
        other = drive_state(moved, m.q, m.qd, m.qdd)
        exact = (other.current - state.current) / 1e-3
        assert np.abs(currents[k] - exact).max() < 0.005 * np.abs(exact).max()
        exact = (other.tau_sim - state.tau_sim) / 1e-3
        assert np.abs(torques[k] - exact).max() < 1e-9 + 1e-6 * np.abs(exact).max()
    half = half_widths(u, currents, "current")
    expected = np.hypot(
        t_quantile(9) * np.sqrt(np.sum(currents**2, axis=0)), 1.959963984540054 * 0.05
    )
    np.testing.assert_allclose(half, expected)


def test_the_metrics_spread_is_the_modes_recomputed():
    """BandTally's RMS and R^2 spreads, folded in two chunks, against the metrics recomputed
    with the predictions moved by each mode."""
    rng = np.random.default_rng(3)
    measured = rng.normal(size=(400, 2)) + np.linspace(0, 3, 400)[:, None]
    predicted = measured + 0.1 * rng.normal(size=(400, 2))
    shifts = 0.05 * rng.normal(size=(5, 400, 2))
    half = np.full((400, 2), 0.2)
    tally = BandTally(5, 2)
    tally.add(measured[:150], predicted[:150], shifts[:, :150], half[:150])
    part = BandTally(5, 2)
    part.add(measured[150:], predicted[150:], shifts[:, 150:], half[150:])
    tally.merge(part)
    band = tally.result()

    def rms(p):
        return np.sqrt(np.mean((measured - p) ** 2, axis=0))

    def r2(p):
        sst = np.sum((measured - measured.mean(axis=0)) ** 2, axis=0)
        return 1 - np.sum((measured - p) ** 2, axis=0) / sst

    moved = [predicted + shifts[k] for k in range(5)]
    rms_std = np.sqrt(sum((rms(p) - rms(predicted)) ** 2 for p in moved))
    r2_std = np.sqrt(sum((r2(p) - r2(predicted)) ** 2 for p in moved))
    np.testing.assert_allclose(band.rms, rms(predicted))
    np.testing.assert_allclose(band.rms_std, rms_std, rtol=1e-9)
    np.testing.assert_allclose(band.r2_std, r2_std, rtol=1e-9)
    inside = np.mean(np.abs(measured - predicted) <= 0.2, axis=0)
    np.testing.assert_allclose(band.inside, inside)
    assert band.samples == 400


def test_validate_carries_the_band_and_a_builtin_model_says_no_interval(ur5e, tmp_path):
    """On the twin's test B: the band of a model with errors in the report, its JSON (method,
    per joint coverage) and plots; a built-in model's report says "no interval"."""
    robot = _with_errors(ur5e)
    model = tmp_path / "model.toml"
    from kinergy.model.toml import save_robot

    save_robot(robot, model)
    report = kinergy.validate(model, ["test-b"], plots=tmp_path / "plots")
    band = report.band
    assert band is not None and band.note is None and "t quantile" in band.method
    for signal in (band.current, band.torque):
        assert signal is not None and signal.samples == report.samples
        assert all(0.0 <= x <= 1.0 for x in signal.inside)
        assert all(h > 0 for h in signal.half_width)
    data = json.loads(json.dumps(report.to_dict(), default=str))
    assert data["band"]["level"] == 0.95 and len(data["band"]["current"]["inside"]) == 6
    assert data["logs"][0]["band"]["current"]["samples"] == report.samples
    assert (tmp_path / "plots" / "test-b_current.png").exists()
    plain = kinergy.validate(ur5e, ["test-b"])
    assert plain.band is not None and plain.band.note == NO_BAND and plain.band.current is None
    assert "no interval" in plain.to_dict()["band"]["note"]


def test_the_residual_survives_the_robot_file(ur5e):
    robot = _with_errors(ur5e)
    back = robot_from_dict(robot_to_dict(robot))
    assert back.uncertainty.residual == robot.uncertainty.residual
    bad = robot_to_dict(robot)
    bad["uncertainty"]["residual"] = {"current": [-1.0] * 6}
    with pytest.raises(kinergy.KinergyError, match="uncertainty.residual"):
        robot_from_dict(bad)


def test_a_report_without_plots_folds_the_band_in_any_chunks(ur5e):
    """The band's figures do not depend on the chunks (one pass, bounded memory)."""
    from kinergy.logs.prepare import prepare
    from kinergy.twin import simulate

    robot = _with_errors(ur5e)
    log = simulate(ur5e, paper_trajectory(ur5e, "test-b"))
    data = prepare(log, robot.n)
    whole = validation_report(robot, [data]).band
    pieces = validation_report(robot, [data], rows=997).band
    assert whole is not None and pieces is not None
    np.testing.assert_allclose(whole.current.rms_std, pieces.current.rms_std, rtol=1e-9)
    np.testing.assert_allclose(whole.current.inside, pieces.current.inside)


def test_energy_plot_shades_the_supply_powers_band(ur5e, tmp_path):
    """energy --plot's band on the supply power: for a model whose only error is its standing
    draw (std 2 W), t x 2 W at every sample; for one with drive errors, the band's integral over
    the motion is at least the energy interval's half-width (|int D g| <= int |D g|); the PNG is
    written."""
    from kinergy.accounting.trace import PowerSeries
    from kinergy.io.rtde import write_log
    from kinergy.twin import simulate
    from kinergy.workflows.energy import SupplyBand, energy_of_log

    log = simulate(ur5e, paper_trajectory(ur5e, "test-b"))
    path = tmp_path / "b.csv"
    write_log(path, log.t, log.signals)
    standby = Uncertainty(("standby_power",), np.array([[2.0]]), 9, "test")
    for robot in (dataclasses.replace(ur5e, uncertainty=standby), _with_errors(ur5e)):
        series = PowerSeries()
        figures = energy_of_log(robot, path, band=SupplyBand(robot, series))
        half = series.predicted
        assert half.size == series.t.size > 100
        if robot.uncertainty is standby:
            np.testing.assert_allclose(half, t_quantile(9) * 2.0)
        else:
            integral = float(np.sum(0.5 * np.diff(series.t) * (half[1:] + half[:-1])))
            assert integral >= figures.intervals.drawn.half_width > 0
    model = tmp_path / "model.toml"
    from kinergy.model.toml import save_robot

    save_robot(_with_errors(ur5e), model)
    kinergy.energy(model, path, plot=tmp_path / "supply.png")
    assert (tmp_path / "supply.png").stat().st_size > 0


def test_validate_prints_the_band_or_no_interval(ur5e, tmp_path, capsys):
    from kinergy.cli import main
    from kinergy.model.toml import save_robot

    model = tmp_path / "model.toml"
    save_robot(_with_errors(ur5e), model)
    assert main(["validate", str(model), "test-b"]) == 0
    out = capsys.readouterr().out
    assert "95 % prediction band: t quantile (9 degrees of freedom)" in out
    assert "measured inside" in out and "RMS [A] ± std" in out
    assert main(["validate", "ur5e", "test-b"]) == 0
    out = capsys.readouterr().out
    assert "95 % prediction band: the model carries no parameter errors" in out
    assert "no interval" in out
