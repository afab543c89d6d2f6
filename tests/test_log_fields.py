"""Logs as their loggers write them (issue 34, point 1; issue 38, point 3).

RTDE's output fields are known by their widths (UR's RTDE guide, as UR's client library types
them); a header log's columns that are no RTDE field are ignored with one note and never
converted; a known field kinergy does not use may hold text; the did-you-mean refusal is kept
for a name close to a field the command needs and the log lacks; a header log with its own names
is mapped with ``--columns FIELD=COLUMN`` and reads the same as the RTDE-named one; measured
accelerations (``actual_qdd``) are used where logged.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from clicase import run_case

from kinergy.errors import KinergyError
from kinergy.io.columns import ColumnMap, parse_column_spec
from kinergy.io.fields import FIELDS, JOINTS, is_known, vector_member
from kinergy.io.formats import read_log
from kinergy.io.motion import motion_from_log
from kinergy.io.rtde import write_log
from kinergy.logs.reading import CheckedLog, LogReading
from kinergy.model import load_robot
from kinergy.trajectory.programs import paper_trajectory
from kinergy.twin import TwinSettings, simulate

#: UR's RTDE output fields with their types (UR's RTDE guide; ur_client_library's
#: data_package.cpp types them): a sample across every group, width by type
RTDE_GUIDE = {
    "timestamp": 1,
    "target_q": JOINTS,
    "actual_current_as_torque": JOINTS,
    "joint_mode": JOINTS,
    "actual_TCP_acceleration": 6,
    "tcp_offset": 6,
    "ft_raw_wrench": 6,
    "wrench_calc_from_currents": 6,
    "target_base_wrench": 6,
    "payload_inertia": 6,
    "payload_cog": 3,
    "target_gravity": 3,
    "elbow_velocity": 3,
    "payload": 1,
    "script_control_line": 1,
    "runtime_state": 1,
    "robot_mode": 1,
    "safety_mode": 1,
    "speed_scaling": 1,
    "target_speed_fraction": 1,
    "joint_position_deviation_ratio": 1,
    "actual_robot_voltage": 1,
    "actual_robot_current": 1,
    "actual_main_voltage": 1,
    "actual_robot_energy_consumed": 1,
    "actual_execution_time": 1,
    "control_step": 1,
    "actual_configurable_digital_output_bits": 1,
    "tool_output_voltage": 1,
    "tool_digital_output": 1,
    "output_bit_registers0_to_31": 1,
    "output_bit_registers32_to_63": 1,
}


def test_rtde_output_fields_are_known_with_their_widths() -> None:
    for name, width in RTDE_GUIDE.items():
        assert FIELDS.get(name) == width, name
    registers = [
        *(f"output_int_register_{k}" for k in range(48)),
        *(f"output_double_register_{k}" for k in range(48)),
        *(f"output_bit_register_{k}" for k in range(64, 128)),
        *(f"input_double_register_{k}" for k in (0, 47)),
    ]
    assert all(is_known(r) for r in registers)
    for unknown in ("output_int_register_48", "output_bit_register_3", "speed_scaling_combined"):
        assert not is_known(unknown), unknown
    # a scalar whose name ends in a number is no vector's member
    assert vector_member("output_bit_registers0_to_31") is None
    assert vector_member("payload_cog_2") == ("payload_cog", 2)
    assert vector_member("payload_cog_3") is None
    assert vector_member("actual_q_6") == ("actual_q", 6)


def _twin(n: int = 600) -> tuple[np.ndarray, dict[str, np.ndarray]]:
    robot = load_robot("ur5e")
    log = simulate(robot, paper_trajectory(robot, "test-a"), TwinSettings(seed=4))
    return log.t[:n], {k: v[:n] for k, v in log.signals.items()}


def _write(path: Path, header: list[str], rows: list[list[str]], sep: str = ",") -> Path:
    lines = [sep.join(header), *(sep.join(r) for r in rows)]
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")
    return path


def _columns(t: np.ndarray, signals: dict[str, np.ndarray]) -> tuple[list[str], np.ndarray]:
    names = ["timestamp"]
    cols = [t[:, None]]
    for name, x in signals.items():
        if x.ndim == 1:
            names.append(name)
            cols.append(x[:, None])
        else:
            names += [f"{name}_{k}" for k in range(x.shape[1])]
            cols.append(x)
    return names, np.hstack(cols)


def _logger_file(path: Path, *, order: int | None = None) -> Path:
    """The twin's log as another lab's logger writes it: a wall-clock string first, RTDE's
    registers and a user's own column besides, in the file's own column order (``order``:
    the columns shuffled, seeded)."""
    t, signals = _twin()
    names, values = _columns(t, signals)
    n = len(t)
    rng = np.random.default_rng(0)
    extra = {
        "output_bit_registers0_to_31": rng.integers(0, 2**31, n).astype(float),
        "output_int_register_12": rng.integers(-5, 5, n).astype(float),
        "output_double_register_3": rng.normal(size=n),
        "script_control_line": np.arange(n) % 7 + 1.0,
        "my_station": np.full(n, 3.0),
    }
    names += list(extra)
    values = np.hstack([values, np.column_stack(list(extra.values()))])
    cells = [[f"{v:.10g}" for v in row] for row in values]
    header = ["_id", *names]
    rows = [[f"2021:10:05:12:08:{5 + 0.002 * i:09.6f}", *c] for i, c in enumerate(cells)]
    if order is not None:
        perm = [0, *np.random.default_rng(order).permutation(np.arange(1, len(header)))]
        header = [header[k] for k in perm]
        rows = [[r[k] for k in perm] for r in rows]
    return _write(path, header, rows)


@pytest.mark.parametrize("order", [None, 7])
def test_another_loggers_columns_are_read_and_the_rest_named_once(
    tmp_path: Path, order: int | None
) -> None:
    path = _logger_file(tmp_path / "lab.csv", order=order)
    checked = CheckedLog(path, load_robot("ur5e"), LogReading())
    log = checked.read()
    t, signals = _twin()
    np.testing.assert_allclose(log.t, t, rtol=0, atol=1e-9)
    np.testing.assert_allclose(log["actual_current"], signals["actual_current"], atol=1e-8)
    assert "output_bit_registers0_to_31" in log.signals and "output_int_register_12" in log
    notes = [n for n in checked.notes if "ignored" in n]
    assert len(notes) == 1 and "_id" in notes[0] and "my_station" in notes[0], checked.notes
    assert "output_int_register" not in notes[0]


def test_a_text_column_is_refused_only_where_kinergy_reads_numbers(tmp_path: Path) -> None:
    t, signals = _twin(50)
    names, values = _columns(t, {"actual_q": signals["actual_q"]})
    cells = [[f"{v:.10g}" for v in row] for row in values]
    unused = _write(
        tmp_path / "bits.csv",
        [*names, "actual_digital_input_bits"],
        [[*c, f"0x{i:02X}"] for i, c in enumerate(cells)],
    )
    log = read_log(unused)
    assert "actual_digital_input_bits" not in log.signals
    assert "not numbers, and not used" in log.notes[0]
    used = _write(
        tmp_path / "mode.csv",
        [*names, "robot_mode"],
        [[*c, "RUNNING"] for c in cells],
    )
    with pytest.raises(KinergyError, match=r"line 2, column 8 \(robot_mode\): not a finite number"):
        read_log(used)


def test_a_misspelt_column_is_refused_only_when_the_command_needs_the_field(
    tmp_path: Path,
) -> None:
    t, signals = _twin(400)
    signals["actual_curent"] = signals.pop("actual_current")
    path = tmp_path / "typo.csv"
    write_log(path, t, signals)
    robot = load_robot("ur5e")
    needs = ["actual_q", "actual_qd", "actual_current"]
    with pytest.raises(KinergyError, match=r"actual_curent_0 .*did you mean actual_current\?"):
        CheckedLog(path, robot, LogReading(), select=needs).read()
    checked = CheckedLog(path, robot, LogReading(), select=["target_q", "target_qd"])
    checked.read()  # the energy of the commanded motion does not need the currents
    assert any("actual_curent_0" in n for n in checked.notes)


def _own_names(path: Path, t: np.ndarray, signals: dict[str, np.ndarray]) -> Path:
    """The log with a lab's own names: time, positions_1..6, velocities_1..6, currents_1..6,
    moments_1..6 (numbered from 1)."""
    own = {"actual_q": "positions", "actual_qd": "velocities", "actual_current": "currents"}
    own["target_moment"] = "moments"
    header = ["time"]
    cols = [t[:, None]]
    for name, label in own.items():
        header += [f"{label}_{k + 1}" for k in range(6)]
        cols.append(signals[name])
    rows = [[f"{v:.10g}" for v in row] for row in np.hstack(cols)]  # as write_log writes
    return _write(path, header, rows, sep=" ")


MAP = "timestamp=time,actual_q=positions_*,actual_qd=velocities_*,actual_current=currents_*,target_moment=moments_*"


def test_a_header_log_with_its_own_names_reads_as_the_rtde_named_one(tmp_path: Path) -> None:
    t, signals = _twin()
    path = _own_names(tmp_path / "own.csv", t, signals)
    rtde = tmp_path / "rtde.csv"
    keep = ("actual_q", "actual_qd", "actual_current", "target_moment")
    write_log(rtde, t, {k: signals[k] for k in keep})
    robot = load_robot("ur5e")
    spec = parse_column_spec(MAP, robot.n)
    assert isinstance(spec, ColumnMap)
    mapped = CheckedLog(path, robot, LogReading(columns=spec)).read()
    named = CheckedLog(rtde, robot, LogReading()).read()
    assert set(mapped.signals) == set(named.signals)
    for name in named.signals:
        np.testing.assert_array_equal(mapped[name], named[name])
    # without the mapping: refused, saying how to map
    with pytest.raises(KinergyError, match="no 'timestamp' column.*--columns timestamp=COLUMN"):
        read_log(path)


@pytest.mark.parametrize(
    ("spec", "message"),
    [
        ("timestamp=time,actual_q=positions", "actual_q is a vector: write actual_q=positions_\\*"),
        (
            "timestamp=time,actual_qq=positions_*",
            "unknown field 'actual_qq' .did you mean actual_q",
        ),
        ("timestamp=time*", "timestamp is one value"),
        (
            "timestamp=time,actual_q=positions_*,actual_qd=positions_*",
            "positions_\\* is mapped twice",
        ),
        ("timestamp=time,actual_q:6", "beside FIELD=COLUMN entries"),
        ("timestamp=", "must be FIELD=COLUMN"),
    ],
)
def test_a_bad_mapping_is_one_line(spec: str, message: str) -> None:
    with pytest.raises(KinergyError, match=message):
        parse_column_spec(spec, 6)


@pytest.mark.parametrize(
    ("spec", "message"),
    [
        ("timestamp=clock", "the header has no column clock .it names time, positions_1"),
        ("timestamp=time,actual_q=pos_*", "no column of the header matches"),
        ("timestamp=time,joint_temperatures=positions_*", None),
        ("timestamp=time,actual_q=currents_*,actual_current=currents_*", "mapped twice"),
    ],
)
def test_a_mapping_the_header_does_not_fit_is_one_line(
    tmp_path: Path, spec: str, message: str | None
) -> None:
    t, signals = _twin(50)
    path = _own_names(tmp_path / "own.csv", t, signals)
    if message is None:  # a field mapped to columns the header has: fine
        log = read_log(path, columns=parse_column_spec(spec, 6))
        assert log["joint_temperatures"].shape == (50, 6)
        return
    with pytest.raises(KinergyError, match=message):
        read_log(path, columns=parse_column_spec(spec, 6))


def test_a_mapping_counts_the_joints_and_wants_consecutive_numbers(tmp_path: Path) -> None:
    t, signals = _twin(50)
    path = _own_names(tmp_path / "own.csv", t, signals)
    with pytest.raises(KinergyError, match="matches 6 columns, but actual_q has 7"):
        read_log(path, columns=parse_column_spec("timestamp=time,actual_q=positions_*", 7))
    text = path.read_text().replace("positions_4", "positions_9")
    path.write_text(text)
    with pytest.raises(KinergyError, match="numbered 1, 2, 3, 5, 6, 9: not consecutive"):
        read_log(path, columns=parse_column_spec("timestamp=time,actual_q=positions_*", 6))


def test_the_mapping_on_the_command_line(tmp_path: Path) -> None:
    t, signals = _twin()
    _own_names(tmp_path / "own.csv", t, signals)
    case = run_case(["energy", "ur5e", "own.csv", "--columns", MAP, "--json"], tmp_path)
    assert case.status == 0, case.err
    headerless = tmp_path / "h.csv"
    headerless.write_text("0 1 2\n0.002 1 2\n")
    case = run_case(["energy", "ur5e", "h.csv", "--columns", MAP], tmp_path)
    assert case.status != 0 and "FIELD=COLUMN maps a header's names" in case.err


def test_measured_accelerations_are_used_where_logged() -> None:
    t, signals = _twin()
    qdd = np.random.default_rng(3).normal(size=signals["actual_q"].shape)
    from kinergy.io.log import Log

    log = Log("mem", t, {"actual_q": signals["actual_q"], "actual_qd": signals["actual_qd"]})
    with_qdd = Log("mem", t, {**log.signals, "actual_qdd": qdd})
    assert np.array_equal(motion_from_log(with_qdd, source="actual").qdd, qdd)
    assert not np.allclose(motion_from_log(log, source="actual").qdd, qdd)
    # identification's preparation filters the logged acceleration as it filters the speed
    from kinergy.logs.filtering import default_cutoff, lowpass
    from kinergy.logs.prepare import prepare

    d = prepare(Log("mem", t, {**with_qdd.signals, "actual_current": signals["actual_current"]}), 6)
    fs = 1.0 / float(t[1] - t[0])
    np.testing.assert_allclose(d.qdd, lowpass(qdd, fs, default_cutoff(t)), atol=1e-12)


def test_a_mapping_leaves_columns_unread_with_an_underscore(tmp_path: Path) -> None:
    path = _logger_file(tmp_path / "lab.csv")
    spec = parse_column_spec("_=output_double_register_3,_=my_station,_=actual_current_*", 6)
    checked = CheckedLog(path, load_robot("ur5e"), LogReading(columns=spec))
    log = checked.read()
    assert "output_double_register_3" not in log.signals and "actual_current" not in log.signals
    note = next(n for n in checked.notes if "ignored" in n)
    assert "_id" in note and "my_station" not in note  # what the user left out is not noted
