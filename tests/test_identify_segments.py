"""Identification never filters or differentiates across a gap (issue 15): a log with a one-hour
gap is prepared segment by segment, says so, and identifies as its two parts given as two logs."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import kinergy
from kinergy.identification.sequential import identify_sequential
from kinergy.io.rtde import write_log
from kinergy.logs.reading import LogReading
from kinergy.model import load_robot
from kinergy.trajectory.programs import paper_trajectory
from kinergy.twin import simulate
from kinergy.workflows.logs import prepared_logs


def test_a_log_with_a_gap_is_identified_as_its_segments(
    tmp_path: Path, ur5e: kinergy.Robot
) -> None:
    twin = simulate(ur5e, paper_trajectory(ur5e, "test-a", dt=0.002))
    t = np.concatenate([twin.t, twin.t + twin.t[-1] + 3600.0])
    signals = {k: np.concatenate([v, v]) for k, v in twin.signals.items()}
    joined, single = tmp_path / "gap.csv", tmp_path / "one.csv"
    write_log(joined, t, signals)
    write_log(single, twin.t, twin.signals)

    ur5e = load_robot("ur5e")
    parts, inputs = prepared_logs([joined], ur5e, LogReading())
    twice = prepared_logs([single], ur5e, LogReading())[0] * 2  # the same log, each part once
    notes = [n for n in inputs.notes if "segments" in n]
    assert len(parts) == 2
    assert len(notes) == 1 and "2 segments (gaps up to 3600.000 s)" in notes[0]
    for got, want in zip(parts, twice, strict=True):
        assert got.qdd_cmd.shape == want.qdd_cmd.shape
        np.testing.assert_allclose(got.qdd_cmd, want.qdd_cmd, rtol=1e-12, atol=1e-12)

    a = identify_sequential(ur5e, parts).to_dict()["joints"]
    b = identify_sequential(ur5e, twice).to_dict()["joints"]
    for ja, jb in zip(a, b, strict=True):
        # the second part's time stamps are shifted by an hour: equal up to their round-off
        assert ja["torque_constant"] == pytest.approx(jb["torque_constant"], rel=1e-8)
        assert ja["rotor_inertia"] == pytest.approx(jb["rotor_inertia"], rel=1e-8)
