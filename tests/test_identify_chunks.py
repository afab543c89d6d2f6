"""Every identification method is one fold over chunks: what a method identifies does not depend
on how its logs were cut. Logs read in chunks of 1 row, of 997 rows, and prepared whole (one
chunk each, the in-memory entry points) give the same result, to round-off: the chunks are
folded into QR triangles in another order, which moves the last bits (:data:`RTOL`), never more.
The logs have what makes chunking hard: a gap (two segments), samples where no program runs,
irregular time stamps, friction held through standstill (whose memory crosses chunk edges).

One thing is compared otherwise: where the full method writes its links from the physically
consistent fit (a semidefinite program), the standard parameters the data do not see (the parts
of the links outside the base parameters, a rotor inertia merged with a link's) are settled by
that program's small regularisation, to its solver's tolerance: chunks folded in another order
move them by up to 1e-4 of the base parameters' scale in those directions (the same as solving
the same program with another tolerance does). So for the full method the regression's
unknowns are compared (to 1e-8 of their standard errors, or of their values when the target
is noise-free), the constrained fit's chi^2, and the
written model's predictions of the logs (to 1e-6), not each number of the file."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pytest

from kinergy.identification.chunks import History, LogChunks, WholeSegment
from kinergy.identification.drive_steps import _Signals, signal_history
from kinergy.identification.full import FullFit
from kinergy.identification.options import IdentifyOptions, Method, Solver, Target
from kinergy.identification.payload import identify_payload
from kinergy.identification.result import IdentificationResult
from kinergy.identification.sequential import identify_sequential
from kinergy.io.rtde import write_log
from kinergy.logs.prepare import spill_log
from kinergy.logs.reading import CheckedLog, LogReading
from kinergy.model import Payload, Robot, load_robot
from kinergy.trajectory.programs import paper_trajectory
from kinergy.twin import TwinSettings, realistic_truth, simulate
from kinergy.workflows.identify import identify_logs, identify_model, identify_payload_model
from kinergy.workflows.logs import chunked_logs, prepared_logs

#: relative agreement of every number the model file gets, whatever the chunks: round-off of the
#: QR triangles folded in another order (measured: below 1.3e-11)
RTOL = 1e-8


def _written(robot: Robot) -> dict[str, float]:
    """Every number of a model's links and drives and its standby power, by name."""
    out = {"standby_power": float(robot.standby_power)}
    for j, joint in enumerate(robot.joints):
        out[f"{j}.mass"] = float(joint.link.mass)
        for k, c in enumerate(joint.link.com):
            out[f"{j}.com{k}"] = float(c)
        for k, c in enumerate(joint.link.inertia):
            out[f"{j}.inertia{k}"] = float(c)
        for f in dataclasses.fields(joint.drive):
            value = getattr(joint.drive, f.name)
            if isinstance(value, float | int) and not isinstance(value, bool):
                out[f"{j}.{f.name}"] = float(value)
        for name, value in joint.drive.friction.params.items():
            out[f"{j}.friction.{name}"] = float(value)
        out[f"{j}.friction.model={joint.drive.friction.name}"] = 0.0
    return out


def _assert_same(got: Robot, want: Robot, rtol: float = RTOL) -> None:
    """Every number agrees to ``rtol``; numbers that are zero but for round-off (a centre of
    mass or an inertia product on an axis) to ``rtol`` of the largest of the same link."""
    a, b = _written(got), _written(want)
    assert a.keys() == b.keys()
    for key in a:
        joint = key.split(".")[0]
        size = max(abs(v) for k, v in b.items() if k.split(".")[0] == joint)
        assert a[key] == pytest.approx(b[key], rel=rtol, abs=1e-12 * size), key


def _log(path: Path, robot: Robot, dt: float, payload: Payload | None = None) -> Path:
    """A realistic twin log of test A at ``dt`` with a gap (two segments), samples where the
    robot is not running at its start, and jittered time stamps in its second segment."""
    truth = realistic_truth(robot, seed=3)
    if payload is not None:
        truth = truth.with_payload(payload)
    twin = simulate(truth, paper_trajectory(robot, "test-a", dt=dt), TwinSettings.realistic(seed=3))
    n = twin.t.size
    rng = np.random.default_rng(5)
    jitter = rng.uniform(-0.1, 0.1, n) * dt * (np.arange(n) % 7 == 3)
    second = twin.t + twin.t[-1] + 60.0 + jitter
    t = np.concatenate([twin.t, second])
    signals = {k: np.concatenate([v, v]) for k, v in twin.signals.items()}
    if "robot_mode" in signals:
        signals["robot_mode"][:40] = 5  # idle (brakes on) before the program
    write_log(path, t, signals)
    return path


@pytest.fixture(scope="module")
def ur5e() -> Robot:
    return load_robot("ur5e")


@pytest.fixture(scope="module")
def twin_log(tmp_path_factory: pytest.TempPathFactory, ur5e: Robot) -> Path:
    return _log(tmp_path_factory.mktemp("chunks") / "twin.csv", ur5e, 0.002)


@pytest.fixture(scope="module")
def short_log(tmp_path_factory: pytest.TempPathFactory, ur5e: Robot) -> Path:
    """The same at 125 Hz: 3,400 rows, for chunks of one row."""
    return _log(tmp_path_factory.mktemp("chunks") / "short.csv", ur5e, 0.008)


CASES = {
    "sequential": IdentifyOptions(),
    "sequential power_law": IdentifyOptions(friction="power_law"),
    "friction auto": IdentifyOptions(friction="auto"),
    "full": IdentifyOptions(Method.FULL),
    "full current wls": IdentifyOptions(Method.FULL, target=Target.CURRENT, solver=Solver.WLS),
}


def _identify_whole(path: Path, robot: Robot, options: IdentifyOptions) -> IdentificationResult:
    datas, _ = prepared_logs([path], robot, LogReading())
    return identify_model(robot, datas, options)


def _assert_same_result(got: IdentificationResult, want: IdentificationResult) -> None:
    """What the method identified agrees (module docstring)."""
    if not isinstance(want.fit, FullFit):
        _assert_same(got.robot, want.robot)
        return
    assert isinstance(got.fit, FullFit)
    x = np.array([p.value for p in got.fit.parameters])
    y = np.array([p.value for p in want.fit.parameters])
    std = np.array([p.std or 0.0 for p in want.fit.parameters])
    # noise-free target_moment: standard errors are round-off too, the values are compared (and
    # a parameter near zero to round-off of the largest)
    close = 1e-8 * std + 1e-9 * np.abs(y) + 1e-12 * np.abs(y).max()
    assert np.all(np.abs(x - y) <= close)
    if want.fit.physical_fit is not None:
        assert got.fit.physical_fit is not None
        assert got.fit.physical_fit.chi2_increase == pytest.approx(
            want.fit.physical_fit.chi2_increase, rel=1e-6, abs=1e-9
        )
    for key in ("torque", "current"):
        for a, b in zip(getattr(got.fit, key), getattr(want.fit, key), strict=True):
            assert a.rms == pytest.approx(b.rms, rel=1e-6)


@pytest.mark.parametrize("case", CASES)
def test_997_rows_and_whole_logs_give_the_same_model(
    twin_log: Path, tmp_path: Path, ur5e: Robot, case: str
) -> None:
    options = CASES[case]
    whole = _identify_whole(twin_log, ur5e, options)
    chunked = identify_logs(ur5e, [twin_log], tmp_path / "m.toml", options=options, rows=997)
    _assert_same_result(chunked, whole)
    _assert_same(load_robot(tmp_path / "m.toml"), chunked.robot, rtol=1e-15)


@pytest.mark.parametrize("case", ["sequential", "full current wls"])
def test_chunks_of_one_row_give_the_same_model(short_log: Path, ur5e: Robot, case: str) -> None:
    options = CASES[case]
    whole = _identify_whole(short_log, ur5e, options)
    _assert_same_result(identify_logs(ur5e, [short_log], None, options=options, rows=1), whole)


def test_the_fit_record_does_not_depend_on_the_chunks(twin_log: Path, ur5e: Robot) -> None:
    datas, read = prepared_logs([twin_log], ur5e, LogReading())
    whole = identify_model(ur5e, datas)
    chunked = identify_logs(ur5e, [twin_log], None, rows=997)
    assert chunked.inputs.notes == read.notes and any("2 segments" in n for n in read.notes)
    assert chunked.fit.logs == whole.fit.logs and chunked.fit.samples == whole.fit.samples
    np.testing.assert_allclose(chunked.fit.lag, whole.fit.lag, rtol=1e-9)
    for key in ("torque", "current"):
        for got, want in zip(getattr(chunked.fit, key), getattr(whole.fit, key), strict=True):
            np.testing.assert_allclose(
                [got.mean, got.max, got.rms, got.r2],
                [want.mean, want.max, want.rms, want.r2],
                rtol=1e-8,
            )
    assert chunked.fit.warnings == whole.fit.warnings
    assert len(chunked.fit.notes) == len(whole.fit.notes)


def test_the_payload_does_not_depend_on_the_chunks(tmp_path: Path, ur5e: Robot) -> None:
    path = _log(tmp_path / "loaded.csv", ur5e, 0.004, Payload(mass=2.0, com=[0.01, -0.02, 0.05]))
    model = tmp_path / "m.toml"
    truth = realistic_truth(ur5e, seed=3)  # the arm the twin simulated, without the payload
    whole = identify_payload(truth, prepared_logs([path], ur5e, LogReading())[0])
    chunked = identify_payload_model(truth, [path], model, rows=997)
    for got, want in zip([chunked.payload], whole[1:], strict=True):
        np.testing.assert_allclose(
            [got.mass, got.mass_std, *got.com, *got.com_std],
            [want.mass, want.mass_std, *want.com, *want.com_std],
            rtol=1e-8,
        )
    assert chunked.payload.mass == pytest.approx(2.0, rel=0.02)


def test_friction_held_through_standstill_crosses_chunks(twin_log: Path, ur5e: Robot) -> None:
    """With the hold on, each chunk's columns and predictions recall the last moving sample
    of the chunks before it; the result equals the whole logs' (chunks of one log held whole)."""
    from kinergy.identification.options import Hold

    datas, _ = prepared_logs([twin_log], ur5e, LogReading())
    whole = identify_sequential(ur5e, datas, hold=Hold.FULL)
    assert all(j.drive.friction.params.get("holding") == 1.0 for j in whole.robot.joints)
    from kinergy.identification.options import CurrentOptions
    from kinergy.identification.sequential import sequential
    from kinergy.workflows.identify import measured_electrics

    logs = LogChunks([WholeSegment(d) for d in datas], rows=700, spool=True)
    chunked = sequential(ur5e, logs, CurrentOptions(hold=Hold.FULL))
    _assert_same(chunked.robot, whole.robot)
    _assert_same(
        measured_electrics(chunked, logs).robot,
        measured_electrics(whole, LogChunks.of(datas)).robot,
    )
    for got, want in zip(chunked.fit.current, whole.fit.current, strict=True):
        assert got.rms == pytest.approx(want.rms, rel=1e-9)
    logs.close()


def test_prepared_chunks_equal_the_prepared_segments(twin_log: Path, ur5e: Robot) -> None:
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


def test_the_spills_are_removed(twin_log: Path, ur5e: Robot) -> None:
    spill = spill_log(CheckedLog(twin_log, ur5e, rows=1000))
    name = Path(f"/proc/self/fd/{spill.file.fileno()}").resolve()
    assert len(spill) > 1000 and spill.read(10, 12).t.size == 2
    spill.close()
    assert not name.exists()
    datas, _ = prepared_logs([twin_log], ur5e, LogReading())
    logs = LogChunks([WholeSegment(d) for d in datas], rows=5000, spool=True)
    assert sum(len(c) for _, c in logs.chunks()) == sum(len(d) for d in datas)
    assert logs.store.file is not None
    kept = Path(f"/proc/self/fd/{logs.store.file.fileno()}").resolve()
    logs.close()
    assert not kept.exists()


def test_a_first_pass_left_early_keeps_nothing(twin_log: Path, ur5e: Robot) -> None:
    datas, _ = prepared_logs([twin_log], ur5e, LogReading())
    logs = LogChunks([WholeSegment(d) for d in datas], rows=1000, spool=False)
    for _ in logs.chunks():
        break
    assert len(logs.store) == 0 and logs.owner == []
    assert sum(len(c) for _, c in logs.chunks()) == sum(len(d) for d in datas)
    assert [s.samples for s in logs.summaries] == [len(d) for d in datas]


@pytest.mark.parametrize("seed", range(20))
def test_the_history_holds_every_chunk_as_the_whole_sequence(seed: int) -> None:
    """Friction held through standstill over a sequence cut into random chunks, with the
    samples the history puts in front of each, equals the hold over the whole sequence: short
    runs (the filter's overshoot, below MIN_RUN), runs across chunk edges, long stops."""
    from kinergy.friction.standstill import hold

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
    history: History[_Signals] = signal_history(1.0)
    cuts = np.sort(rng.choice(np.arange(1, n), size=25, replace=False))
    parts = []
    for lo, hi in zip([0, *cuts], [*cuts, n], strict=True):
        chunk = _Signals(other[lo:hi], wm[lo:hi], dwm[lo:hi], np.zeros(hi - lo))
        joined, skip = history.ahead(0, chunk)
        parts.append(held(joined.wm, joined.dwm, joined.tau_load)[skip:])
        history.update(joined, skip)
    np.testing.assert_array_equal(np.vstack(parts), whole)
