"""Energy in one pass (issue 16) and never across a gap (issue 15): a log read in small chunks
gives the in-memory figures, and a log with a one-hour gap gives the sum of its two parts."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pytest
from scipy.integrate import trapezoid

import kinergy
from kinergy.accounting.energy import energy, trapezoid_weights
from kinergy.cli import main
from kinergy.io.rtde import read_log, write_log
from kinergy.trajectory.programs import paper_trajectory
from kinergy.twin import simulate
from kinergy.workflows.energy import EnergyOptions, energy_of_log
from kinergy.workflows.logs import read_motion

#: the measured motion of a log
ACTUAL = EnergyOptions(source="actual")

RTOL = 1e-9


def _leaves(d: Any, where: str = "") -> dict[str, Any]:
    if isinstance(d, dict):
        return {k: v for key, x in d.items() for k, v in _leaves(x, f"{where}.{key}").items()}
    if isinstance(d, list):
        return {k: v for i, x in enumerate(d) for k, v in _leaves(x, f"{where}[{i}]").items()}
    return {where: d}


def _assert_same(got: dict[str, Any], want: dict[str, Any], rtol: float = RTOL) -> None:
    g, w = _leaves(got), _leaves(want)
    assert set(g) == set(w)
    for key, value in w.items():
        if isinstance(value, float):
            assert g[key] == pytest.approx(value, rel=rtol, abs=1e-12), key
        else:
            assert g[key] == value, key


@pytest.fixture(scope="module")
def long_log(tmp_path_factory: pytest.TempPathFactory, ur5e: kinergy.Robot) -> Path:
    """A 20 s, 500 Hz twin log (noisy actual signals, target ones, supply, temperatures)."""
    path = tmp_path_factory.mktemp("stream") / "long.csv"
    twin = simulate(ur5e, paper_trajectory(ur5e, "test-a", dt=0.002, rest=3.43))
    assert twin.t[-1] - twin.t[0] == pytest.approx(20.0, abs=0.01)
    write_log(path, twin.t, twin.signals)
    return path


@pytest.mark.parametrize("source", ["target", "actual"])
@pytest.mark.parametrize("recovery", [True, False])
def test_chunks_of_any_size_give_the_whole_logs_figures(
    ur5e: kinergy.Robot, long_log: Path, source: str, recovery: bool
) -> None:
    # actual: accelerations from a spline of the noisy speed, carried across chunk boundaries
    whole = energy_of_log(ur5e, long_log, None, EnergyOptions(source, recovery), rows=10**7)
    got = energy_of_log(ur5e, long_log, None, EnergyOptions(source, recovery), rows=1000)
    want = whole.to_dict()
    assert got.samples == want["samples"] >= 10_000 and got.segments == 1
    assert "measured" in want
    _assert_same(got.to_dict(), want)
    # energy() of the log's motion held in memory: the same accounting as one chunk
    motion, _ = read_motion(long_log, ur5e, source=source)
    temperature = read_log(long_log)["joint_temperatures"]
    held = energy(ur5e, motion, recovery=recovery, temperature=temperature).to_dict()
    own = ("measured", "inputs", "notes", "warnings")  # what only reading the log knows
    _assert_same(held, {k: v for k, v in want.items() if k not in own})


def test_a_gap_is_never_integrated_across(
    ur5e: kinergy.Robot, long_log: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    a = simulate(ur5e, paper_trajectory(ur5e, "test-a", dt=0.002))
    b = simulate(ur5e, paper_trajectory(ur5e, "test-b", dt=0.002), name="b")
    parts = {"a": tmp_path / "a.csv", "b": tmp_path / "b.csv", "ab": tmp_path / "ab.csv"}
    write_log(parts["a"], a.t, a.signals)
    t_b = b.t - b.t[0] + a.t[-1] + 3600.0  # an hour later
    write_log(parts["b"], t_b, b.signals)
    joined = {k: np.concatenate([a[k], b[k]]) for k in a.signals}
    write_log(parts["ab"], np.concatenate([a.t, t_b]), joined)
    one = {k: energy_of_log(ur5e, p, None, ACTUAL, rows=1000) for k, p in parts.items()}
    ab, sa, sb = one["ab"], one["a"], one["b"]
    assert ab.segments == 2 and sa.segments == sb.segments == 1
    assert ab.duration == pytest.approx(sa.duration + sb.duration, rel=1e-12)
    assert ab.span - ab.duration == pytest.approx(3600.0, rel=1e-9)
    np.testing.assert_allclose(ab.e_elec, sa.e_elec + sb.e_elec, rtol=RTOL)
    np.testing.assert_allclose(ab.e_mech, sa.e_mech + sb.e_mech, rtol=RTOL)
    assert ab.total_e_elec == pytest.approx(sa.total_e_elec + sb.total_e_elec, rel=RTOL)
    assert ab.supply.drawn == pytest.approx(sa.supply.drawn + sb.supply.drawn, rel=RTOL)
    assert ab.measured is not None and sa.measured is not None and sb.measured is not None
    assert ab.measured.drawn == pytest.approx(sa.measured.drawn + sb.measured.drawn, rel=RTOL)
    # read whole, the log splits the same way
    whole = energy_of_log(ur5e, parts["ab"], None, ACTUAL, rows=10**7)
    _assert_same(ab.to_dict(), whole.to_dict())
    assert main(["energy", "ur5e", str(parts["ab"])]) == 0
    text = capsys.readouterr().out
    assert "2 segments; gaps of 3600.000 s not integrated." in text
    assert main(["energy", "ur5e", str(parts["a"])]) == 0
    assert "segments" not in capsys.readouterr().out


@pytest.mark.parametrize(
    ("dropped", "note"),
    [
        (
            ("target_qd", "target_qdd"),
            "target_qd not in the log: speeds and accelerations from a spline of target_q",
        ),
        (("target_qdd",), "target_qdd not in the log: accelerations from a spline of target_qd"),
    ],
)
def test_a_motion_derived_from_positions_is_said_and_close(
    ur5e: kinergy.Robot, long_log: Path, tmp_path: Path, dropped: tuple[str, ...], note: str
) -> None:
    log = read_log(long_log)
    path = tmp_path / "fewer.csv"
    write_log(path, log.t, {k: v for k, v in log.signals.items() if k not in dropped})
    full = energy_of_log(ur5e, long_log, None, EnergyOptions("target"))
    fewer = energy_of_log(ur5e, path, None, EnergyOptions("target"))
    assert f"{path}: {note}" in fewer.notes
    assert not any("spline" in n for n in full.notes)
    # the spline of the commanded positions gives the commanded motion's energy closely
    assert fewer.supply.drawn == pytest.approx(full.supply.drawn, rel=1e-3)
    np.testing.assert_allclose(fewer.e_elec, full.e_elec, rtol=2e-3)


def test_the_trapezoid_weights_are_scipys_trapezoid_rule() -> None:
    rng = np.random.default_rng(7)
    t = np.cumsum(rng.uniform(0.001, 0.003, 1000))
    y = rng.standard_normal((1000, 5))
    np.testing.assert_allclose(trapezoid_weights(t) @ y, trapezoid(y, t, axis=0), rtol=1e-12)
    assert trapezoid_weights(t[:1]) @ y[:1] == pytest.approx(np.zeros(5))
