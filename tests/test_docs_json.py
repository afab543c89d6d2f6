"""The JSON contract page (docs/json.md) lists every key each ``--json`` prints, and no other.

The page's tables give key paths (``joints[].e_mech``); a path part ``{like-this}`` stands for
keys named by data and is checked against what it may name (a friction parameter, a command's
option, ...); a row that links to a record (``#record-...``) holds that record's keys. The
documents compared are every file in ``tests/golden/`` (which hold the commands' output) and
runs of the commands that the golden files do not cover: ``--friction auto`` with a joint that
never moves, the full method against measured joint torques by weighted least squares, a log
with a gap, a URScript program, a calibration file, an excitation compared with random ones,
a placement search, the nursing method (through the Python API, whose ``to_dict()`` is the command's JSON without
the ``kinergy`` record), a fleet and a live monitor against the protocol-level RTDE server.

Checked both ways: every key printed is on the page (under its command's heading), and every
row of the page is printed by some document; every command with ``--json`` has a heading; every
golden file is compared.
"""

from __future__ import annotations

import contextlib
import io
import json
import re
import sys
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import click
import numpy as np
import pytest

from kinergy.api import identify as api_identify
from kinergy.api import simulate as api_simulate
from kinergy.cli.app import cli, main
from kinergy.friction.registry import MODELS
from kinergy.model.library import load_robot
from kinergy.model.robot import SOURCE_CATEGORIES

ROOT = Path(__file__).resolve().parents[1]
PAGE = ROOT / "docs" / "json.md"
GOLDEN = ROOT / "tests" / "golden"
DATASETS = ROOT.parent / "shared" / "datasets"
CALIBRATION = DATASETS / "ur5e-calibration" / "robot_calibration_summary.txt"

sys.path.insert(0, str(Path(__file__).parent))
from rtde_server import RtdeServer  # noqa: E402

Path_ = tuple[str, ...]

#: which golden file is the output of which command (the page's heading anchors)
GOLDEN_SECTIONS = {
    "robot_list": "json-robot-list",
    "robot_show_ur5e": "json-robot-show",
    "robot_show_ur5e_payload": "json-robot-show",
    "robot_show_panda": "json-robot-show",
    "robot_show_nursing-arm": "json-robot-show",
    "identify_sequential": "json-identify",
    "identify_full": "json-identify",
    "identify_full_current": "json-identify",
    "identify_payload": "json-identify",
    "ur10e_identify_sequential": "json-identify",
    "validate_sequential": "json-validate",
    "ur10e_validate": "json-validate",
    "energy_test_a": "json-energy",
    "energy_test_a_no_recovery": "json-energy",
    "optimize_test_a": "json-optimize",
    "excite_small": "json-excite",
    "nursing_exact": "json-nursing",
}

_INERTIAL = re.compile(r"(m|mx|my|mz|Ixx|Iyy|Izz|Ixy|Iyz|Ixz)\d+")
_FRICTION_PARAMETERS = {p for m in MODELS.values() for p in m.parameters} | {
    "standstill",
    "holding",
}


# ---------------------------------------------------------------------------------------------
# the page


@dataclass
class Row:
    """One table row: its key path, the record it holds (if it links to one) and whether a
    document printed it."""

    key: str
    path: Path_
    record: str | None
    used: bool = False


_HEADING = re.compile(r"^#{2,3} .*\{#([\w-]+)\}\s*$")
_ROW = re.compile(r"^\| `([^`]+)` \|(.*)\|\s*$")
_RECORD = re.compile(r"\]\(#(record-[\w-]+)\)")


def _tokens(key: str) -> Path_:
    """``joints[].drive.friction`` -> ``("joints", "[]", "drive", "friction")``."""
    out: list[str] = []
    for part in key.split("."):
        name = part.replace("[]", "")
        if name:
            out.append(name)
        out += ["[]"] * part.count("[]")
    return tuple(out)


def read_page(text: str) -> dict[str, list[Row]]:
    """The page's sections (heading anchor -> its rows)."""
    sections: dict[str, list[Row]] = {}
    current: list[Row] | None = None
    for line in text.splitlines():
        heading = _HEADING.match(line)
        if heading:
            current = sections.setdefault(heading.group(1), [])
            continue
        row = _ROW.match(line)
        if row and current is not None:
            record = _RECORD.search(row.group(2))
            current.append(Row(row.group(1), _tokens(row.group(1)), record and record.group(1)))
    return sections


# ---------------------------------------------------------------------------------------------
# matching printed keys to rows


def _command(document: Any) -> click.Command | None:
    """The click command that printed ``document`` (from its ``kinergy`` record)."""
    if not isinstance(document, dict) or "kinergy" not in document:
        return None
    command: click.Command | None = cli
    ctx = click.Context(cli)
    for word in document["kinergy"]["command"].split()[1:]:
        assert isinstance(command, click.Group)
        command = command.get_command(ctx, word)
    return command


def _placeholders(command: click.Command | None) -> dict[str, Callable[[str], bool]]:
    options = {p.name for p in command.params} if command is not None else set()
    return {
        "parameter": lambda k: k in _FRICTION_PARAMETERS,
        "model": lambda k: k in MODELS,
        "category": lambda k: k in SOURCE_CATEGORIES,
        "inertial": lambda k: _INERTIAL.fullmatch(k) is not None,
        "option": lambda k: k in options,
    }


def _match(pattern: Path_, path: Path_, valid: dict[str, Callable[[str], bool]]) -> bool:
    if len(pattern) != len(path):
        return False
    for want, got in zip(pattern, path, strict=True):
        if want.startswith("{") and want.endswith("}"):
            if got == "[]" or not valid[want[1:-1]](got):
                return False
        elif want != got:
            return False
    return True


def _covered(
    path: Path_,
    rows: list[Row],
    records: dict[str, list[Row]],
    valid: dict[str, Callable[[str], bool]],
) -> bool:
    """Whether ``path`` is documented by ``rows`` (or a record they hold); marks the rows."""
    found = False
    for row in rows:
        if _match(row.path, path, valid) or _match(row.path, (*path, "[]"), valid):
            row.used = found = True
            continue
        if row.record is None or len(row.path) >= len(path):
            continue
        if _match(row.path, path[: len(row.path)], valid):
            rest = path[len(row.path) :]
            while rest and rest[0] == "[]":
                rest = rest[1:]
            if not rest or _covered(rest, records[row.record], records, valid):
                found = True
    return found


def key_paths(value: Any, prefix: Path_ = ()) -> Iterator[Path_]:
    """Every key path of a JSON document (a list's elements under ``[]``)."""
    if isinstance(value, dict):
        for key, item in value.items():
            yield (*prefix, key)
            yield from key_paths(item, (*prefix, key))
    elif isinstance(value, list):
        if prefix == ():
            yield ("[]",)
        for item in value:
            yield from key_paths(item, (*prefix, "[]"))


def undocumented(document: Any, section: str, sections: dict[str, list[Row]]) -> list[str]:
    """The key paths of ``document`` that section ``section`` does not document."""
    records = {k: v for k, v in sections.items() if k.startswith("record-")}
    valid = _placeholders(_command(document))
    missing = {
        ".".join(path).replace(".[]", "[]")
        for path in key_paths(document)
        if not _covered(path, sections[section], records, valid)
    }
    return sorted(missing)


# ---------------------------------------------------------------------------------------------
# the documents


def _run(argv: list[str]) -> Any:
    buffer = io.StringIO()
    with contextlib.redirect_stdout(buffer):
        status = main(argv)
    assert status == 0, f"kinergy {' '.join(argv)} exited {status}"
    return json.loads(buffer.getvalue())


def _monitor_run() -> Any:
    """``kinergy monitor --json`` against the RTDE test server serving a repeating program."""
    from kinergy.trajectory.motion import Motion
    from kinergy.trajectory.movej import movej
    from kinergy.trajectory.programs import UR_HOME, pad_rest
    from kinergy.twin import TwinSettings, simulate

    robot = load_robot("ur5e")
    step = np.array([[0.0] * 6, [0.8, 0.3, -0.5, 0.2, 0.6, 0.0], [-0.5, 0.2, 0.4, 0, 0, 1]])
    way = np.vstack([UR_HOME + step, UR_HOME])
    cycle = pad_rest(movej(way, speed=2.0, acceleration=5.0, dt=0.002), 0.1, 0.002)
    n = len(cycle.t) - 1
    idx = np.arange(n) % n
    motion = Motion(500.0 + 0.002 * np.arange(n), cycle.q[idx], cycle.qd[idx], cycle.qdd[idx])
    with RtdeServer(simulate(robot, motion, TwinSettings(seed=0))) as server:
        return _run(["monitor", server.address, "--model", "ur5e", "--duration", "7", "--json"])


def _fleet_run(folder: Path) -> Any:
    from kinergy.fleet.twin import twin_fleet

    manifest = twin_fleet(
        folder / "fleet", robots=1, days=4, logs=4, seconds=6.0, programs=["short"],
        payload={"robot-01": (2, 5.0)}, seed=1,
    )  # fmt: skip
    argv = ["fleet", "energy", "--manifest", str(manifest), "--out", str(folder / "f.parquet")]
    return _run([*argv, "--workers", "1", "--json"])


def _twin_logs(folder: Path) -> dict[str, Path]:
    """Test A on the UR5e twin; the same with measured joint torques; with a 1 s gap; and a
    run in which wrist 3 never moves."""
    from kinergy.io.rtde import read_log, write_log
    from kinergy.trajectory.motion import Motion
    from kinergy.trajectory.programs import paper_trajectory

    logs = {name: folder / f"{name}.csv" for name in ("a", "torque", "gap", "still")}
    assert main(["simulate", "ur5e", "--trajectory", "test-a", "--out", str(logs["a"])]) == 0
    log = read_log(logs["a"])
    write_log(logs["torque"], log.t, {**log.signals, "actual_joint_torque": log["target_moment"]})
    t = log.t.copy()
    t[len(t) // 2 :] += 1.0
    write_log(logs["gap"], t, dict(log.signals))
    robot = load_robot("ur5e")
    m = paper_trajectory(robot, "test-a")
    q, qd, qdd = m.q.copy(), m.qd.copy(), m.qdd.copy()
    q[:, 5], qd[:, 5], qdd[:, 5] = q[0, 5], 0.0, 0.0
    still = api_simulate(robot, Motion(m.t, q, qd, qdd)).log
    write_log(logs["still"], still.t, still.signals)
    return logs


def _robot_file(folder: Path) -> list[str]:
    """``robot show --json`` of a robot file that gives the optional winding resistances and
    motor-side torque sensors (what the twin's ``target_moment`` read as measured torques is)."""
    import tomli_w

    from kinergy.model.toml import robot_to_dict

    data = robot_to_dict(load_robot("ur5e"))
    for joint in data["joints"]:
        joint["drive"]["winding_resistance"] = 0.5  # ohm
        joint["torque_sensor"] = {"side": "motor", "offset": 0.0}
    path = folder / "with-resistance.toml"
    path.write_text(tomli_w.dumps(data), encoding="utf-8")
    return ["robot", "show", str(path), "--json"]


def _nursing_result() -> Any:
    """The nursing method on the coupled twin: its Table 6 excitation and one friction run."""
    from kinergy.api import IdentifyOptions, SimulateOptions
    from kinergy.experiments.friction_runs import back_and_forth_motion
    from kinergy.experiments.nursing_excitation import table6_motion

    arm = load_robot("nursing-arm")
    motion, _, _ = table6_motion(arm, periods=2, dt=0.004)
    exact = SimulateOptions(exact=True)
    excitation = api_simulate(arm, motion, exact).log
    run = api_simulate(arm, back_and_forth_motion(arm, 0).motion, exact).log
    nursing = IdentifyOptions(method="nursing")  # type: ignore[arg-type]
    return json.loads(json.dumps(api_identify([excitation, run], arm, nursing).to_dict()))


@pytest.fixture(scope="module")
def documents(tmp_path_factory: pytest.TempPathFactory) -> dict[str, list[tuple[str, Any]]]:
    """Section anchor -> (name, document) of every output compared."""
    out: dict[str, list[tuple[str, Any]]] = {}
    for name, section in GOLDEN_SECTIONS.items():
        document = json.loads((GOLDEN / f"{name}.json").read_text(encoding="utf-8"))
        out.setdefault(section, []).append((name, document))
    folder = tmp_path_factory.mktemp("docs-json")
    logs = {k: str(v) for k, v in _twin_logs(folder).items()}
    runs = {
        "json-identify": {
            "auto, a joint still": [
                "identify", logs["still"], "--robot", "ur5e", "--friction", "auto",
                "--out", str(folder / "auto.toml"), "--json",
            ],
            "full, joint torques, wls": [
                "identify", logs["torque"], "--robot", str(folder / "with-resistance.toml"),
                "--method", "full",
                "--target", "torque", "--solver", "wls", "--accept", "robot",
                "--out", str(folder / "full.toml"), "--json",
            ],
        },
        "json-validate": {
            "joint torques": [
                "validate", str(folder / "with-resistance.toml"), logs["torque"], "--accept",
                "robot", "--json",
            ],
        },
        "json-energy": {
            "a gap": ["energy", "ur5e", logs["gap"], "--json"],
            "an identified model": ["energy", str(folder / "auto.toml"), logs["a"], "--json"],
        },
        "json-optimize": {
            "URScript": [
                "optimize", "ur5e", str(ROOT / "tests" / "programs" / "small.script"),
                "--pareto-points", "0", "--json",
            ],
            "URScript, an identified model": [
                "optimize", str(folder / "auto.toml"),
                str(ROOT / "tests" / "programs" / "small.script"), "--json",
            ],
        },
        "json-place": {
            "a small grid": [
                "place", "ur5e", str(ROOT / "tests" / "programs" / "small.script"),
                "--x", "-0.1:0.1", "--y", "0.0:0.9", "--step", "0.45", "--tool-symmetry", "z",
                "--json",
            ],
        },
        "json-excite": {
            "compared": [
                "excite", "ur5e", "--harmonics", "3", "--period", "6", "--starts", "1",
                "--maxiter", "5", "--samples", "60", "--compare", "2", "--quiet", "--json",
                "--out", str(folder / "excitation.csv"),
            ],
        },
    }  # fmt: skip
    if CALIBRATION.exists():
        runs["json-robot-import-calibration"] = {
            "ur5e calibration": [
                "robot", "import-calibration", "ur5e", str(CALIBRATION),
                "--out", str(folder / "cal.toml"), "--json",
            ],
        }  # fmt: skip
    runs["json-robot-show"] = {"a robot file with winding resistances": _robot_file(folder)}
    for section, argvs in runs.items():
        for name, argv in argvs.items():
            out.setdefault(section, []).append((name, _run(argv)))
    out["json-identify"].append(("nursing (Python API)", _nursing_result()))
    out.setdefault("json-fleet-energy", []).append(("fleet", _fleet_run(folder)))
    out.setdefault("json-monitor", []).append(("monitor", _monitor_run()))
    return out


# ---------------------------------------------------------------------------------------------
# the tests


def test_every_key_printed_is_on_the_page(documents: dict[str, list[tuple[str, Any]]]) -> None:
    sections = read_page(PAGE.read_text(encoding="utf-8"))
    problems = [
        f"{section} ({name}): {key}"
        for section, docs in documents.items()
        for name, document in docs
        for key in undocumented(document, section, sections)
    ]
    assert not problems, "keys printed but not in docs/json.md:\n" + "\n".join(problems)


def test_every_key_on_the_page_is_printed(documents: dict[str, list[tuple[str, Any]]]) -> None:
    sections = read_page(PAGE.read_text(encoding="utf-8"))
    for section, docs in documents.items():
        for _, document in docs:
            undocumented(document, section, sections)
    unused = [
        f"{section}: {row.key}"
        for section, rows in sections.items()
        if section in documents or section.startswith("record-")
        for row in rows
        if not row.used
    ]
    assert not unused, "keys in docs/json.md that no command printed:\n" + "\n".join(unused)


def _json_commands(group: click.Group, prefix: str = "") -> Iterator[str]:
    ctx = click.Context(group)
    for name in group.list_commands(ctx):
        command = group.get_command(ctx, name)
        assert command is not None
        if isinstance(command, click.Group):
            yield from _json_commands(command, f"{prefix}{name} ")
        elif any(p.name == "as_json" for p in command.params):
            yield f"{prefix}{name}"


def test_every_json_command_has_a_section() -> None:
    sections = read_page(PAGE.read_text(encoding="utf-8"))
    missing = [
        name for name in _json_commands(cli) if "json-" + name.replace(" ", "-") not in sections
    ]
    assert not missing, f"commands with --json missing from docs/json.md: {missing}"


def test_every_golden_file_is_compared() -> None:
    names = {p.stem for p in GOLDEN.glob("*.json")}
    assert names == set(GOLDEN_SECTIONS), (
        f"golden files not compared: {sorted(names - set(GOLDEN_SECTIONS))}; "
        f"gone: {sorted(set(GOLDEN_SECTIONS) - names)}"
    )


def test_the_comparison_can_fail() -> None:
    """A key the page lacks is reported, a row under a record or a placeholder covers only
    what it may name, and an unused row stays unused."""
    page = "\n".join(
        [
            "## a {#record-x}",
            "| `mean` | N m | |",
            "## b {#json-b}",
            "| `joints[]` | object | |",
            "| `joints[].stats` | [x](#record-x) | |",
            "| `joints[].friction.{parameter}` | | |",
            "| `never` | | |",
        ]
    )
    sections = read_page(page)
    document = {
        "joints": [{"stats": [{"mean": 1.0, "max": 2.0}], "friction": {"viscous": 1, "x": 2}}],
        "extra": 1,
    }
    assert undocumented(document, "json-b", sections) == [
        "extra",
        "joints[].friction",
        "joints[].friction.x",
        "joints[].stats[].max",
    ]
    assert [r.key for r in sections["json-b"] if not r.used] == ["never"]
