"""Identification in chunks (issue 16) equals identification of the whole logs: every parameter the
model file gets agrees to 1e-9 relative, for logs cut into many small chunks, with segments, with
samples where no program runs, with irregular time stamps, and with friction held through
standstill (whose memory crosses chunk edges)."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pytest

import kinergy
from kinergy.identify.sequential import identify_sequential, sequential_from
from kinergy.identify.streamed import LogsInChunks, WholeSegment, streams
from kinergy.io.rtde import write_log
from kinergy.logs.prepare import spill_log
from kinergy.logs.reading import CheckedLog, LogReading
from kinergy.model import Robot, load_robot
from kinergy.simulate import TwinSettings, realistic_truth, simulate
from kinergy.trajectory.programs import paper_trajectory
from kinergy.workflows.identify import identify_logs, identify_model, measured_electrics
from kinergy.workflows.logs import chunked_logs, prepared_logs

RTOL = 1e-9


def _written(robot: Robot) -> dict[str, float]:
    """Every number of a model's drives and its standby power, by name."""
    out = {"standby_power": float(robot.standby_power)}
    for j, joint in enumerate(robot.joints):
        for f in dataclasses.fields(joint.drive):
            value = getattr(joint.drive, f.name)
            if isinstance(value, float | int) and not isinstance(value, bool):
                out[f"{j}.{f.name}"] = float(value)
        for name, value in joint.drive.friction.params.items():
            out[f"{j}.friction.{name}"] = float(value)
        out[f"{j}.friction.model={joint.drive.friction.model}"] = 0.0
    return out


def _assert_same(got: Robot, want: Robot) -> None:
    a, b = _written(got), _written(want)
    assert a.keys() == b.keys()
    for key in a:
        assert a[key] == pytest.approx(b[key], rel=RTOL, abs=1e-300), key


@pytest.fixture(scope="module")
def twin_log(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A realistic twin log of test A with a gap (two segments), samples where the program is
    not running at its start, and jittered time stamps in its second segment (resampled)."""
    model = load_robot("ur5e")
    twin = simulate(
        realistic_truth(model, seed=3),
        paper_trajectory(model, "test-a", dt=0.002),
        TwinSettings.realistic(seed=3),
    )
    n = twin.t.size
    rng = np.random.default_rng(5)
    second = twin.t + twin.t[-1] + 60.0 + rng.uniform(-2e-4, 2e-4, n) * (np.arange(n) % 7 == 3)
    t = np.concatenate([twin.t, second])
    signals = {k: np.concatenate([v, v]) for k, v in twin.signals.items()}
    if "runtime_state" in signals:
        signals["runtime_state"][:40] = 1
    path = tmp_path_factory.mktemp("stream") / "twin.csv"
    write_log(path, t, signals)
    return path


def test_the_default_identify_streams() -> None:
    ur5e = load_robot("ur5e")
    assert streams(ur5e, "sequential", None)
    assert streams(ur5e, "sequential", "viscous_coulomb")
    assert not streams(ur5e, "sequential", "auto")
    assert not streams(ur5e, "sequential", "power_law")  # its exponent is searched
    assert not streams(ur5e, "full", None)


@pytest.mark.parametrize("rows", [997, 4000])
def test_streamed_identify_equals_in_memory(twin_log: Path, tmp_path: Path, rows: int) -> None:
    ur5e = load_robot("ur5e")
    datas, read = prepared_logs([twin_log], ur5e, LogReading())
    whole = identify_model(ur5e, datas)
    chunked = identify_logs(ur5e, [twin_log], tmp_path / "b.toml", rows=rows)
    assert chunked.inputs.notes == read.notes and "2 segments" in read.notes[0]
    _assert_same(chunked.robot, whole.robot)
    _assert_same(load_robot(tmp_path / "b.toml"), whole.robot)
    assert chunked.fit.logs == whole.fit.logs and chunked.fit.samples == whole.fit.samples
    np.testing.assert_allclose(chunked.fit.lag, whole.fit.lag, rtol=RTOL)
    for key in ("torque", "current"):
        for got, want in zip(getattr(chunked.fit, key), getattr(whole.fit, key), strict=True):
            np.testing.assert_allclose(
                [got.mean, got.max, got.rms, got.r2],
                [want.mean, want.max, want.rms, want.r2],
                rtol=1e-8,
            )
    assert chunked.fit.warnings == whole.fit.warnings and chunked.fit.notes == whole.fit.notes


def test_prepared_chunks_equal_the_prepared_segments(twin_log: Path) -> None:
    ur5e = load_robot("ur5e")
    datas, _ = prepared_logs([twin_log], ur5e, LogReading())
    with chunked_logs([twin_log], ur5e, LogReading(), rows=1500) as (segments, _):
        assert [s.path for s in segments] == [d.path for d in datas]
        for segment, data in zip(segments, datas, strict=True):
            parts = list(segment.chunks(1500))
            assert len(parts) > 1
            assert segment.lag == pytest.approx(data.lag, rel=1e-12, abs=1e-15)
            for name in ("t", "q_cmd", "qdd_cmd", "q", "qd", "qdd", "current", "voltage"):
                got = np.concatenate([getattr(p, name) for p in parts])
                np.testing.assert_allclose(got, getattr(data, name), rtol=1e-12, atol=1e-12)


def test_friction_held_through_standstill_crosses_chunks(twin_log: Path) -> None:
    """With the hold on, each chunk's columns and predictions recall the last moving sample
    of the chunks before it; the result equals the whole logs' (chunks of one log held whole)."""
    ur5e = load_robot("ur5e")
    datas, _ = prepared_logs([twin_log], ur5e, LogReading())
    whole = identify_sequential(ur5e, datas, hold=True)
    logs = LogsInChunks(ur5e, [WholeSegment(d) for d in datas], rows=700)
    chunked = sequential_from(ur5e, logs, hold=True)
    assert all(j.drive.friction.params.get("holding") == 1.0 for j in whole.robot.joints)
    _assert_same(chunked.robot, whole.robot)
    _assert_same(measured_electrics(chunked, logs).robot, measured_electrics(whole, datas).robot)
    for got, want in zip(chunked.fit.current, whole.fit.current, strict=True):
        assert got.rms == pytest.approx(want.rms, rel=1e-9)


def test_the_spill_is_removed(twin_log: Path) -> None:
    spill = spill_log(CheckedLog(twin_log, load_robot("ur5e"), rows=1000))
    name = Path(f"/proc/self/fd/{spill.file.fileno()}").resolve()
    assert len(spill) > 1000 and spill.read(10, 12).t.size == 2
    spill.close()
    assert not name.exists()


def test_a_log_without_a_target_is_prepared_whole(tmp_path: Path) -> None:
    ur5e = kinergy.load_robot("ur5e")
    twin = simulate(ur5e, paper_trajectory(ur5e, "test-a", dt=0.002))
    signals = {k: v for k, v in twin.signals.items() if not k.startswith("target_q")}
    path = tmp_path / "actual.csv"
    write_log(path, twin.t, signals)
    whole = identify_model(ur5e, prepared_logs([path], ur5e, LogReading())[0])
    chunked = identify_logs(ur5e, [path], tmp_path / "b.toml", rows=1000)
    _assert_same(chunked.robot, whole.robot)


@pytest.mark.parametrize("seed", range(20))
def test_the_history_holds_every_chunk_as_the_whole_sequence(seed: int) -> None:
    """Friction held through standstill over a sequence cut into random chunks, with the
    samples the history puts in front of each, equals the hold over the whole sequence: short
    runs (the filter's overshoot, below MIN_RUN), runs across chunk edges, long stops."""
    from kinergy.friction.standstill import hold
    from kinergy.identify.drive_steps import _Signals
    from kinergy.identify.streamed import _signal_history

    rng = np.random.default_rng(seed)
    lengths = rng.integers(1, 9, size=120)
    levels = rng.choice([-2.0, -0.4, 0.0, 0.4, 2.0], size=lengths.size)
    wm = np.repeat(levels, lengths) * (1.0 + 0.1 * rng.random(lengths.sum()))
    n = wm.size
    dwm = np.zeros(n)
    other = rng.normal(size=n)
    params = {"standstill": 1.0, "holding": 0.5}

    def held(w: np.ndarray, d: np.ndarray, o: np.ndarray) -> np.ndarray:
        return hold(params, np.column_stack([w, o]), w, d)

    whole = held(wm, dwm, other)
    history = _signal_history(1.0)
    cuts = np.sort(rng.choice(np.arange(1, n), size=25, replace=False))
    parts = []
    for lo, hi in zip([0, *cuts], [*cuts, n], strict=True):
        chunk = _Signals(other[lo:hi], wm[lo:hi], dwm[lo:hi], np.zeros(hi - lo))
        joined, skip = history.ahead(chunk)
        parts.append(held(joined.wm, joined.dwm, joined.tau_load)[skip:])
        history.update(joined, skip)
    np.testing.assert_array_equal(np.vstack(parts), whole)
