"""What the controller logged about itself is used (issue 34, point 2): the payload it logged.

The logged payload (``payload`` kg, ``payload_cog`` m and ``payload_inertia`` kg m² in UR's order
``[Ixx, Iyy, Izz, Ixy, Ixz, Iyz]``, flange frame) is the payload of every command that reads the
log unless ``--payload`` replaces it; a payload that changes inside a log is honoured sample by
sample (energy) or segment by segment (validate; identify refuses logs of several payloads); a
logged payload the arm cannot hold fails the ``ratings`` check.

The dynamics of a logged payload on a rotated flange are checked against Pinocchio built from the
URDF file ``kinergy robot export`` writes of the bare robot, the payload attached in Pinocchio
from UR's definition: independent of kinergy's chain, its payload merging and its reordering of
UR's inertia.
"""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pytest
from clicase import run_case
from conftest import random_state

import kinergy
from kinergy.api import energy, identify, validate
from kinergy.errors import KinergyError
from kinergy.io.formats import read_log
from kinergy.io.log import Log
from kinergy.io.rtde import write_log
from kinergy.logs.payload import logged_loads
from kinergy.logs.reading import CheckedLog, LogReading
from kinergy.model import load_robot, save_robot
from kinergy.model.robot import Payload
from kinergy.trajectory.programs import paper_trajectory
from kinergy.twin import TwinSettings, simulate

DATASETS = Path(__file__).resolve().parents[2] / "shared" / "datasets"
RAD = DATASETS / "ur3e-rad" / "ur3e_rtde_2021-10-05_120805.csv"
needs_rad = pytest.mark.skipif(not RAD.exists(), reason="shared datasets not available")

#: a tool's payload as UR's controller logs it: kg, cog (m), inertia [Ixx,Iyy,Izz,Ixy,Ixz,Iyz]
MASS, COG = 2.3, np.array([0.02, -0.03, 0.07])
UR_INERTIA = np.array([0.011, 0.014, 0.009, 0.002, -0.0015, 0.003])


def _columns(n: int, mass: float = MASS) -> dict[str, np.ndarray]:
    return {
        "payload": np.full(n, mass),
        "payload_cog": np.tile(COG, (n, 1)),
        "payload_inertia": np.tile(UR_INERTIA, (n, 1)),
    }


def _rpy(r: float, p: float, y: float) -> np.ndarray:
    cr, sr, cp, sp, cy, sy = np.cos(r), np.sin(r), np.cos(p), np.sin(p), np.cos(y), np.sin(y)
    rz = np.array([[cy, -sy, 0], [sy, cy, 0], [0, 0, 1]])
    ry = np.array([[cp, 0, sp], [0, 1, 0], [-sp, 0, cp]])
    rx = np.array([[1, 0, 0], [0, cr, -sr], [0, sr, cr]])
    return rz @ ry @ rx


def test_a_logged_payload_on_a_rotated_flange_matches_pinocchio_from_the_exported_urdf(
    tmp_path: Path,
) -> None:
    pin = pytest.importorskip("pinocchio")
    flange = np.eye(4)
    flange[:3, :3] = _rpy(0.4, -0.9, 1.3)
    flange[:3, 3] = [0.01, -0.02, 0.05]
    robot = dataclasses.replace(load_robot("ur5e"), flange=flange)
    save_robot(robot, tmp_path / "rotated.toml")
    args = ["robot", "export", "rotated.toml", "--format", "urdf", "--out", "rotated.urdf"]
    assert run_case(args, tmp_path, outputs=["rotated.urdf"]).status == 0
    model = pin.buildModelFromUrdf(str(tmp_path / "rotated.urdf"))
    model.gravity.linear = robot.gravity
    # the payload in Pinocchio, from UR's meaning of the logged numbers
    frame = model.frames[model.getFrameId("flange")]
    parent = frame.parentJoint if hasattr(frame, "parentJoint") else frame.parent
    ixx, iyy, izz, ixy, ixz, iyz = UR_INERTIA
    matrix = np.array([[ixx, ixy, ixz], [ixy, iyy, iyz], [ixz, iyz, izz]])
    model.appendBodyToJoint(parent, pin.Inertia(MASS, COG, matrix), frame.placement)
    data = model.createData()
    # the same payload as the log holds it, through kinergy
    q, qd, qdd = random_state(robot, 30, seed=11)
    log = Log("tool.csv", np.arange(30) * 0.002, _columns(30))
    loads, index = logged_loads(log)  # type: ignore[misc]
    assert len(loads) == 1 and np.all(index == 0)
    got = kinergy.rnea(robot.with_payload(loads[0]), q, qd, qdd)
    expected = np.array([pin.rnea(model, data, *s) for s in zip(q, qd, qdd, strict=True)])
    assert np.max(np.abs(got - expected)) < 1e-9 * max(1.0, np.max(np.abs(expected)))
    # and the payload is felt: without it the torques differ by far more
    bare = kinergy.rnea(robot, q, qd, qdd)
    assert np.max(np.abs(bare - expected)) > 1.0


def _twin_log(payload: Payload | None, seed: int = 1) -> Log:
    robot = load_robot("ur5e")
    truth = robot.with_payload(payload)
    return simulate(truth, paper_trajectory(robot, "test-a"), TwinSettings(seed=seed))


def test_the_logged_payload_is_the_energy_s_and_the_given_one_replaces_it(tmp_path: Path) -> None:
    payload = Payload(MASS, COG, UR_INERTIA[[0, 1, 2, 3, 5, 4]])
    twin = _twin_log(payload)
    logged = tmp_path / "logged.csv"
    write_log(logged, twin.t, {**twin.signals, **_columns(len(twin.t))})
    bare = tmp_path / "bare.csv"
    write_log(bare, twin.t, twin.signals)
    from_log = energy("ur5e", logged).to_dict()["total"]["e_elec"]
    given = energy("ur5e", bare, reading=LogReading(payload=payload)).to_dict()["total"]["e_elec"]
    without = energy("ur5e", bare).to_dict()["total"]["e_elec"]
    assert from_log == pytest.approx(given, rel=1e-9)
    assert abs(from_log - without) > 0.02 * without
    replaced = energy("ur5e", logged, reading=LogReading(payload="0"))
    assert replaced.to_dict()["total"]["e_elec"] == pytest.approx(without, rel=1e-9)
    assert any("logged payload" in n and "not used" in n for n in replaced.notes)


def _two_payloads(tmp_path: Path) -> tuple[Path, Payload, Payload]:
    """A log of test A carried with 1 kg, then, after a pause of 2 s, with 4 kg."""
    a, b = Payload(1.0, np.array([0, 0, 0.05])), Payload(4.0, np.array([0, 0.02, 0.08]))
    first, second = _twin_log(a, seed=1), _twin_log(b, seed=2)
    t = np.concatenate([first.t, first.t[-1] + 2.0 + second.t])
    signals = {k: np.concatenate([first[k], second[k]]) for k in first.signals}
    n1, n2 = len(first.t), len(second.t)
    signals["payload"] = np.r_[np.full(n1, a.mass), np.full(n2, b.mass)]
    signals["payload_cog"] = np.vstack([np.tile(a.com, (n1, 1)), np.tile(b.com, (n2, 1))])
    path = tmp_path / "two.csv"
    write_log(path, t, signals)
    return path, a, b


def test_a_payload_that_changes_in_a_log_is_honoured(tmp_path: Path) -> None:
    path, a, b = _two_payloads(tmp_path)
    both = energy("ur5e", path).to_dict()["total"]["e_elec"]
    log = read_log(path)
    cut = float(log.t[np.flatnonzero(log["payload"] == b.mass)[0]])
    first = energy("ur5e", path, reading=LogReading(payload=a, window=(None, cut - 1.0)))
    second = energy("ur5e", path, reading=LogReading(payload=b, window=(cut, None)))
    parts = first.to_dict()["total"]["e_elec"] + second.to_dict()["total"]["e_elec"]
    assert both == pytest.approx(parts, rel=1e-6)
    # validate: each segment with its own payload explains the torques
    report = validate("ur5e", [path])
    assert min(m.r2 for m in report.torque) > 0.99
    wrong = validate("ur5e", [path], reading=LogReading(payload="0"))
    assert min(m.r2 for m in wrong.torque) < min(m.r2 for m in report.torque)
    # identify fits one model with one payload: refused, saying what to do
    with pytest.raises(KinergyError, match=r"different payloads \(1 kg .*4 kg.*--from/--to"):
        identify([path], "ur5e")


@pytest.mark.parametrize(
    ("mass", "cog", "message"),
    [
        (40.0, (0, 0, 0.05), r"ratings check failed: the logged payload of 40 kg .* needs \d+ N m"),
        (1.0, (0, 0, 58.0), "ratings check failed: payload_cog is 58 m from the flange"),
        (-1.0, (0, 0, 0.05), "the controller's payload columns hold no load: payload mass"),
    ],
)
def test_a_logged_payload_the_arm_cannot_carry_is_refused(
    mass: float, cog: tuple[float, ...], message: str
) -> None:
    robot = load_robot("ur3e")
    twin = simulate(robot, paper_trajectory(robot, "test-a"), TwinSettings(seed=1))
    n = len(twin.t)
    bad = {"payload": np.full(n, mass), "payload_cog": np.tile(np.array(cog), (n, 1))}
    log = Log("bad.csv", twin.t, {**twin.signals, **bad})
    with pytest.raises(KinergyError, match=message):
        CheckedLog(log, robot, LogReading()).read()


@needs_rad
def test_the_ur3e_rad_log_as_it_is(tmp_path: Path) -> None:
    run = energy("ur3e", RAD)
    notes = [n for n in run.notes if "ignored" in n]
    assert len(notes) == 1 and "(_id)" in notes[0]
    # the logged 1.07 kg is the energy's: without the payload columns, another figure
    header = RAD.read_text().splitlines()[0].split(",")
    keep = [k for k, h in enumerate(header) if not h.startswith("payload")]
    lines = [",".join(line.split(",")[k] for k in keep) for line in RAD.read_text().splitlines()]
    cut = tmp_path / "no-payload.csv"
    cut.write_text("\n".join(lines) + "\n")
    with_payload = run.to_dict()["total"]["e_elec"]
    without = energy("ur3e", cut).to_dict()["total"]["e_elec"]
    assert with_payload > 1.1 * without


def _rad_in_memory(*, payload: bool) -> Log:
    """The ur3e-rad log as read, without ``actual_joint_voltage`` (the joints' bus voltage,
    which motor-resistance fitting must not read: another point of issue 34), with or without
    its logged payload."""
    log = read_log(RAD)
    drop = {"actual_joint_voltage", *(() if payload else ("payload", "payload_cog"))}
    return Log(log.path, log.t, {k: v for k, v in log.signals.items() if k not in drop})


@needs_rad
def test_the_ur3e_rad_fit_uses_the_logged_payload() -> None:
    result = identify([_rad_in_memory(payload=True)], "ur3e")
    r2 = [m.r2 for m in result.fit.torque]
    assert min(r2[:5]) >= 0.99, r2
    assert any("logged payload, 1.07 kg at [0, 0, 0.058] m" in n for n in result.notes)
    assert result.robot.payload is None  # the run's payload is not the arm's: not written
    with pytest.raises(KinergyError, match="fit check failed"):
        identify([_rad_in_memory(payload=False)], "ur3e")
    cut = identify([_rad_in_memory(payload=False)], "ur3e", reading=LogReading(accept="fit"))
    assert min(m.r2 for m in cut.fit.torque[:5]) < 0.5


def test_the_report_and_the_fleet_carry_the_logged_payload(tmp_path: Path) -> None:
    from kinergy.fleet.analysis import _powers
    from kinergy.workflows.energy import log_energy_report

    payload = Payload(MASS, COG, UR_INERTIA[[0, 1, 2, 3, 5, 4]])
    twin = _twin_log(payload)
    logged = Log("logged.csv", twin.t, {**twin.signals, **_columns(len(twin.t))})
    write_log(tmp_path / "logged.csv", logged.t, logged.signals)
    robot = load_robot("ur5e")
    expected = energy(
        robot.with_payload(payload), tmp_path / "logged.csv", reading=LogReading(payload=payload)
    )
    e_elec = expected.to_dict()["total"]["e_elec"]
    report, _ = log_energy_report(robot, tmp_path / "logged.csv")
    assert report.figures().total_e_elec == pytest.approx(e_elec, rel=1e-6)
    bare = _powers(robot, Log("bare", twin.t, twin.signals))["predicted"]
    carried = _powers(robot, logged)["predicted"]
    loaded = _powers(robot.with_payload(payload), Log("bare", twin.t, twin.signals))["predicted"]
    assert bare is not None and carried is not None and loaded is not None
    np.testing.assert_allclose(carried, loaded, rtol=1e-9, atol=1e-9)
    assert not np.allclose(carried, bare)
