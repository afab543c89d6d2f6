"""The one preparation path: a segment's chunks, of any size, equal the whole segment prepared.

Both ways of obtaining the real motion are covered: the commanded motion delayed by the estimated
lag (a twin log with targets) and the measured motion low-pass filtered and differentiated (the
same log without its targets, and a real UR10e log, irregularly sampled). Chunks of 1 row, 997 rows
and the whole segment give the same samples to 1e-12 relative (round-off: the filter and the
spline reach a neighbour's samples with weights below 1e-25).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from kinergy.io.log import Log
from kinergy.logs.prepare import IdentData, prepare_segment, spill_log
from kinergy.logs.reading import CheckedLog, LogReading
from kinergy.model import load_robot
from kinergy.trajectory.programs import paper_trajectory
from kinergy.twin import simulate

UR10E = Path(__file__).resolve().parents[2] / "shared" / "datasets" / "ur10e-innopolis"
FIELDS = ("t", "q_cmd", "qd_cmd", "qdd_cmd", "q", "qd", "qdd", "current", "tau_ref")


def _twin(targets: bool, seconds: float = 6.0) -> Log:
    ur5e = load_robot("ur5e")
    twin = simulate(ur5e, paper_trajectory(ur5e, "test-a"))
    keep = twin.t - twin.t[0] <= seconds
    signals = {
        k: v[keep] for k, v in twin.signals.items() if targets or not k.startswith("target_q")
    }
    return Log("twin", twin.t[keep], signals)


def _same(parts: list[IdentData], whole: IdentData) -> None:
    joined = IdentData.joined(parts)
    assert joined.source == whole.source
    for name in FIELDS:
        got, want = getattr(joined, name), getattr(whole, name)
        if want is None:
            assert got is None
            continue
        scale = max(float(np.max(np.abs(want))), 1e-300)
        np.testing.assert_allclose(got, want, rtol=0, atol=1e-12 * scale, err_msg=name)


def _segment(source: Log | Path, robot: str, reading: LogReading | None = None):
    r = load_robot(robot)
    spill = spill_log(CheckedLog(source, r, reading or LogReading()))
    return spill, prepare_segment(spill, (0, len(spill)), str(source), r.n, None)


@pytest.mark.parametrize("targets", [True, False], ids=["delayed target", "filtered actual"])
@pytest.mark.parametrize("rows", [1, 997])
def test_chunks_equal_the_whole_segment(targets: bool, rows: int) -> None:
    spill, segment = _segment(_twin(targets, seconds=3.0 if rows == 1 else 6.0), "ur5e")
    try:
        whole = segment.whole()
        assert whole.source == ("delayed target" if targets else "filtered actual")
        _same(list(segment.chunks(rows)), whole)
    finally:
        spill.close()


@pytest.mark.skipif(not UR10E.exists(), reason="shared datasets not available")
def test_a_real_irregular_log_filtered_in_chunks_equals_the_whole() -> None:
    from kinergy.io.columns import parse_columns

    spec = "timestamp,actual_q:6,actual_qd:6,actual_current:6,target_current:6,target_moment:6"
    reading = LogReading(columns=tuple(parse_columns(spec, 6)))
    path = UR10E / "validation_data" / "ur-20_01_17-ptp_10_points.csv"
    spill, segment = _segment(path, "ur10e", reading)
    try:
        assert segment.grid is not None  # resampled: the real log's steps are irregular
        _same(list(segment.chunks(997)), segment.whole())
    finally:
        spill.close()
