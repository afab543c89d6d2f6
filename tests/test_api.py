"""The Python API mirrors the commands: the same results, whose ``to_dict()`` is the command's
``--json`` but for the record of the command line (``kinergy``: version, command, options).
Checked on the real UR10e logs (skipped when ../shared/datasets is absent) and on the twin."""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

import pytest

import kinergy
from kinergy.cli import main

UR10E = Path(__file__).resolve().parents[2] / "shared" / "datasets" / "ur10e-innopolis"
SPEC = "timestamp,actual_q:6,actual_qd:6,actual_current:6,target_current:6,target_moment:6"
FOURIER = [
    UR10E / "identification_data" / f"ur-20_02_{n}.csv"
    for n in ("12-50sec_12harm", "19_14harm50sec")
]
HELD_OUT = UR10E / "validation_data" / "ur-20_01_17-ptp_10_points.csv"


def _cli(argv: list[str], capsys: pytest.CaptureFixture[str]) -> dict[str, Any]:
    capsys.readouterr()
    assert main(argv) == 0
    out = json.loads(capsys.readouterr().out)
    assert out.pop("kinergy")["command"].startswith("kinergy ")
    return out


def _plain(x: Any) -> Any:
    """JSON as the command prints it (NaN as null)."""
    return json.loads(json.dumps(x, default=str).replace("NaN", "null"))


def _same(api: Any, cli: Any, where: str = "") -> None:
    if isinstance(cli, dict):
        assert set(api) == set(cli), (where, set(api) ^ set(cli))
        for k in cli:
            _same(api[k], cli[k], f"{where}.{k}")
    elif isinstance(cli, list):
        assert len(api) == len(cli), where
        for k, (a, c) in enumerate(zip(api, cli, strict=True)):
            _same(a, c, f"{where}[{k}]")
    elif isinstance(cli, float) and isinstance(api, float) and not math.isnan(cli):
        assert api == pytest.approx(cli, rel=1e-12, abs=1e-15), where
    else:
        assert api == cli, where


@pytest.mark.skipif(not UR10E.exists(), reason="shared datasets not available")
def test_identify_validate_energy_equal_the_commands(tmp_path, capsys) -> None:
    robot = kinergy.load_robot("ur10e")
    reading = kinergy.LogReading.parse(columns=SPEC)
    result = kinergy.identify(FOURIER, robot, reading=reading, out=tmp_path / "api.toml")
    argv = ["identify", *map(str, FOURIER), "--robot", "ur10e", "--columns", SPEC]
    cli = _cli([*argv, "--out", str(tmp_path / "cli.toml"), "--json"], capsys)
    _same(_plain(result.to_dict()), cli)
    model = kinergy.load_robot(tmp_path / "api.toml")
    assert model.identified is not None and len(model.identified.inputs) == 2

    report = kinergy.validate(model, [HELD_OUT], reading=reading)
    cli = _cli(
        ["validate", str(tmp_path / "api.toml"), str(HELD_OUT), "--columns", SPEC, "--json"], capsys
    )
    cli["inputs"] = [i for i in cli["inputs"] if not i["path"].endswith(".toml")]  # the model file
    _same(_plain(report.to_dict()), cli)

    energy = kinergy.energy(model, HELD_OUT, reading=reading)
    cli = _cli(
        ["energy", str(tmp_path / "api.toml"), str(HELD_OUT), "--columns", SPEC, "--json"], capsys
    )
    cli["inputs"] = [i for i in cli["inputs"] if not i["path"].endswith(".toml")]
    _same(_plain(energy.to_dict()), cli)


def test_read_log_checks_with_a_robot_and_simulate_writes_the_twin() -> None:
    import kinergy.identification.sequential  # a sub-package never shadows the function

    assert callable(kinergy.identify) and callable(kinergy.simulate)
    twin = kinergy.simulate("ur5e", "test-b", kinergy.SimulateOptions(mismatch="realistic", seed=2))
    log = twin.log
    assert len(log) > 1000 and "actual_current" in log
    assert twin.truth.name == "ur5e" and twin.truth != kinergy.load_robot("ur5e")
    with pytest.raises(kinergy.KinergyError, match="test-c"):
        kinergy.simulate("ur5e", "test-c")
    motion_energy = kinergy.energy(
        "ur5e", kinergy.movej([[0] * 6, [1, -1, 1, 0, 1, 0]], speed=1.0, acceleration=2.0, dt=0.002)
    )
    assert motion_energy.total_e_elec > 0 and motion_energy.t.size > 100


@pytest.mark.skipif(not UR10E.exists(), reason="shared datasets not available")
def test_read_log_through_the_checks() -> None:
    log = kinergy.read_log(HELD_OUT, kinergy.LogReading.parse(columns=SPEC), robot="ur10e")
    assert log["actual_q"].shape == (len(log), 6)
    swapped = SPEC.replace("actual_q:6,actual_qd:6", "actual_qd:6,actual_q:6")
    reading = kinergy.LogReading.parse(columns=swapped)
    with pytest.raises(kinergy.KinergyError, match="speeds check failed"):
        kinergy.read_log(HELD_OUT, reading, robot="ur10e")
    assert len(kinergy.read_log(HELD_OUT, reading)) == len(log)  # unchecked without a robot


def test_optimize_program_equals_the_command(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """``kinergy.optimize_program`` on a URScript program and on a task gives the command's JSON;
    a lever's name is parsed (and a wrong one refused) as the flag is."""
    small = Path(__file__).parent / "programs" / "small.script"
    options = kinergy.ProgramOptions(tool_symmetry="z")  # type: ignore[arg-type]
    run = kinergy.optimize_program("ur5e", small, options, urscript=tmp_path / "a.script")
    cli = _cli(
        ["optimize", "ur5e", str(small), "--tool-symmetry", "z", "--json",
         "--urscript", str(tmp_path / "c.script")],
        capsys,
    )  # fmt: skip
    cli.pop("inputs")
    api = _plain(run.to_dict())
    api["written"], cli["written"] = [], []
    _same(api, cli)
    assert (tmp_path / "a.script").read_text() == (tmp_path / "c.script").read_text()
    task = kinergy.optimize_program("ur5e", "test-a", points=0)
    cli = _cli(["optimize", "ur5e", "test-a", "--pareto-points", "0", "--json"], capsys)
    cli.pop("inputs")
    api = _plain(task.to_dict())
    api["solver"].pop("seconds"), cli["solver"].pop("seconds")  # wall time
    _same(api, cli)
    with pytest.raises(kinergy.KinergyError, match="--tool-symmetry: must be one of none, z, z2"):
        kinergy.ProgramOptions(tool_symmetry="z3")  # type: ignore[arg-type]


def test_a_wrong_option_is_one_kinergy_error_naming_it() -> None:
    with pytest.raises(kinergy.KinergyError, match=r"--method: must be one of sequential, full"):
        kinergy.IdentifyOptions(method="payload")  # type: ignore[arg-type]
    with pytest.raises(kinergy.KinergyError, match=r"--target: must be one of auto, moment"):
        kinergy.IdentifyOptions(method="full", target="voltage")  # type: ignore[arg-type]
    free = kinergy.ProgramOptions(via="free")  # type: ignore[arg-type]
    with pytest.raises(kinergy.KinergyError, match=r"--via: only for a URScript program"):
        kinergy.optimize_program("ur5e", "test-a", free)


def test_an_option_the_kind_of_task_does_not_take_is_refused(
    capsys: pytest.CaptureFixture[str],
) -> None:
    """``optimize`` of a task takes no lever of a URScript program, and of a program no Pareto
    front: given, it is refused in one line naming the flag (it was left unused)."""
    small = str(Path(__file__).parent / "programs" / "small.script")
    for argv, flag in (
        (["optimize", "ur5e", "test-a", "--via", "free"], "--via"),
        (["optimize", "ur5e", "test-a", "--tool-symmetry", "z"], "--tool-symmetry"),
        (["optimize", "ur5e", small, "--pareto-points", "3"], "--pareto-points"),
    ):
        assert main(argv) == 1
        err = capsys.readouterr().err
        assert err.startswith(f"kinergy: error: {flag}: only for a") and err.count("\n") == 1


def test_energy_repairs_a_log_cut_short_when_asked(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """The hint of a log cut short names --repair; energy takes it (command and API)."""
    log = tmp_path / "a.csv"
    assert main(["simulate", "ur5e", "--trajectory", "test-a", "--out", str(log)]) == 0
    text = log.read_text()
    log.write_text(text[: text.rindex("\n", 0, len(text) - 1) + 20])  # the last line cut short
    capsys.readouterr()
    assert main(["energy", "ur5e", str(log)]) == 1
    assert "--repair" in capsys.readouterr().err
    assert main(["energy", "ur5e", str(log), "--repair", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    api = kinergy.energy("ur5e", log, reading=kinergy.LogReading(repair=True))
    assert out["samples"] == api.samples == text.count("\n") - 2


def test_identify_payload_equals_the_command(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """``kinergy.identify_payload`` is ``identify --payload-only``: the same JSON and the same
    robot file values, on a twin log of a UR5e carrying 2 kg."""
    import tomllib

    from kinergy.io.rtde import write_log
    from kinergy.model import Payload
    from kinergy.trajectory.programs import paper_trajectory
    from kinergy.twin import TwinSettings, simulate

    ur5e = kinergy.load_robot("ur5e")
    loaded = ur5e.with_payload(Payload(mass=2.0, com=[0.01, -0.02, 0.05]))
    twin = simulate(loaded, paper_trajectory(ur5e, "test-a", dt=0.004), TwinSettings(seed=4))
    log = tmp_path / "loaded.csv"
    write_log(log, twin.t, twin.signals)
    run = kinergy.identify_payload([log], "ur5e", out=tmp_path / "api.toml")
    argv = ["identify", str(log), "--robot", "ur5e", "--payload-only", "--json"]
    cli = _cli([*argv, "--out", str(tmp_path / "cli.toml")], capsys)
    for record in cli["inputs"]:
        record["path"] = str(log)
    _same(_plain(run.to_dict()), cli)
    assert run.payload.mass == pytest.approx(2.0, rel=0.02)
    api, cmd = (
        tomllib.loads((tmp_path / f).read_text())["payload"] for f in ("api.toml", "cli.toml")
    )
    assert api == cmd
    with pytest.raises(kinergy.KinergyError, match="exists: kinergy never replaces a log"):
        kinergy.identify_payload([log], "ur5e", out=log)


# ---------------------------------------------------------------------------------------------
# one front door: the commands parse their flags into the API's options and call it


CLI = Path(kinergy.__file__).parent / "cli"
CALIBRATION = (
    Path(__file__).resolve().parents[2]
    / "shared"
    / "datasets"
    / "ur5e-calibration"
    / "robot_calibration_summary.txt"
)


def test_every_command_calls_the_api() -> None:
    """Each command's module imports the API (``from kinergy import api``) and never a workflow
    (the import-linter contract says the same for every module of the CLI)."""
    import ast

    for path in sorted(CLI.glob("*.py")):
        if path.name in ("__init__.py", "app.py", "common.py"):
            continue
        tree = ast.parse(path.read_text())
        imports = [
            (node.module, [a.name for a in node.names])
            for node in ast.walk(tree)
            if isinstance(node, ast.ImportFrom)
        ]
        assert ("kinergy", ["api"]) in imports, path.name
        assert not [m for m, _ in imports if m and m.startswith("kinergy.workflows")], path.name


def test_the_reading_flags_are_log_reading_parse() -> None:
    """The log-reading flags are built from :meth:`LogReading.parse` (one flag per parameter):
    a command reading logs gets the same :class:`LogReading` as the API is given."""
    import inspect

    from kinergy.cli.common import _READING_FLAGS
    from kinergy.cli.identify import identify

    parameters = set(inspect.signature(kinergy.LogReading.parse).parameters)
    assert set(_READING_FLAGS) == parameters
    flags = {p.name for p in identify.params}
    assert parameters <= flags and "reading" not in flags
    parsed = kinergy.LogReading.parse(
        columns=SPEC, repair=True, cutoff=5.0, accept=["fit,robot"], topic="js", effort="torque"
    )
    assert parsed.columns is not None and parsed.columns[:2] == ("timestamp", "actual_q_0")
    assert {c.value for c in parsed.accept} == {"fit", "robot"}
    assert parsed.bag is not None and parsed.bag.topic == "/js"


@pytest.mark.parametrize(
    ("argv", "build"),
    [
        (
            ["identify", "x.csv", "--robot", "ur5e", "--out", "m.toml", "--ridge", "-1"],
            lambda: kinergy.IdentifyOptions(ridge=-1.0),
        ),
        (
            ["identify", "x.csv", "--robot", "ur5e", "--out", "m.toml", "--cutoff", "0"],
            lambda: kinergy.LogReading(cutoff=0.0),
        ),
        (
            ["validate", "ur5e", "x.csv", "--accept", "nope"],
            lambda: kinergy.LogReading.parse(accept=["nope"]),
        ),
        (
            ["simulate", "ur5e", "--trajectory", "test-a", "--out", "a.csv", "--lag", "7"],
            lambda: kinergy.SimulateOptions(lag=7.0),
        ),
        (
            ["simulate", "ur5e", "--trajectory", "test-a", "--out", "a.csv", "--seed", "-1"],
            lambda: kinergy.SimulateOptions(seed=-1),
        ),
        (
            ["excite", "ur5e", "--out", "m.csv", "--harmonics", "1"],
            lambda: kinergy.api.ExciteOptions(out="m.csv", harmonics=1),
        ),
        (
            ["record", "127.0.0.1", "--out", "r.csv", "--frequency", "1000"],
            lambda: kinergy.api.RecordOptions(frequency=1000.0),
        ),
        (
            ["fleet", "energy", "--manifest", "f.toml", "--out", "f.parquet", "--workers", "0"],
            lambda: kinergy.api.FleetOptions(workers=0),
        ),
        (
            ["nursing", "--seed", "-3"],
            lambda: kinergy.api.NursingStudyOptions(seed=-3),
        ),
        (  # the longest cycle time, once: for a task and a program alike
            ["optimize", "ur5e", "test-a", "--cycle-time", "700"],
            lambda: kinergy.ProgramOptions(cycle_time=700.0),
        ),
        (
            ["place", "ur5e", "p.script", "--x", "0:0", "--y", "0:0", "--v-max", "1e-4"],
            lambda: kinergy.ProgramOptions(v_max=1e-4),
        ),
        (
            ["place", "ur5e", "p.script", "--x", "0:0", "--y", "0:0", "--step", "0"],
            lambda: kinergy.api.PlacementGrid(
                x=kinergy.api.Range(0, 0), y=kinergy.api.Range(0, 0), step=0.0
            ),
        ),
    ],
)
def test_an_option_is_bounded_once(
    argv: list[str], build: Any, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A value out of bounds is refused by its option type: the command (a usage error, exit 2,
    before anything is read or written) and the API say the same line."""
    with pytest.raises(kinergy.KinergyError) as refused:
        build()
    capsys.readouterr()
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err == f"kinergy: error: {refused.value}\n"


def test_excite_equals_the_command(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    small = {"harmonics": 2, "samples": 40, "starts": 1, "maxiter": 5, "compare": 2}
    options = kinergy.api.ExciteOptions(out=tmp_path / "api.csv", **small)
    run = kinergy.api.excite("ur5e", options)
    argv = ["excite", "ur5e", "--quiet", "--json", "--out", str(tmp_path / "cli.csv")]
    cli = _cli([*argv, *(f"--{k}={v}" for k, v in small.items())], capsys)
    assert cli.pop("inputs") == []
    api = _plain(run.to_dict())
    for out in (api, cli):  # the files written and the optimiser's wall time differ
        out.pop("out"), out.pop("seconds")
    _same(api, cli)
    assert (tmp_path / "api.csv").read_text() == (tmp_path / "cli.csv").read_text()


def test_robot_commands_equal_the_api(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    listed = _cli_list(["robot", "list", "--json"], capsys)
    assert listed == _plain([r.to_dict() for r in kinergy.api.robot_list()])
    shown = _cli(["robot", "show", "ur5e", "--payload", "2", "--json"], capsys)
    shown.pop("inputs")
    loaded = kinergy.load_robot("ur5e", payload=kinergy.Payload(mass=2.0))
    _same(_plain(kinergy.api.robot_show(loaded).to_dict()), shown)
    export = kinergy.api.export_robot("ur5e", "mjcf", tmp_path / "api.xml", source="ur5e")
    assert (
        main(["robot", "export", "ur5e", "--format", "mjcf", "--out", str(tmp_path / "c.xml")]) == 0
    )
    assert (tmp_path / "c.xml").read_text() == (tmp_path / "api.xml").read_text() == export.text


@pytest.mark.skipif(not CALIBRATION.exists(), reason="shared datasets not available")
def test_import_calibration_equals_the_command(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    run = kinergy.api.import_calibration("ur5e", CALIBRATION, out=tmp_path / "api.toml")
    argv = ["robot", "import-calibration", "ur5e", str(CALIBRATION), "--json"]
    cli = _cli([*argv, "--out", str(tmp_path / "cli.toml")], capsys)
    cli.pop("inputs", None)
    _same(_plain(run.to_dict()), cli)


def test_simulate_writes_what_the_command_writes(tmp_path: Path) -> None:
    options = kinergy.SimulateOptions(mismatch="realistic", seed=5, lag=0.002)
    twin = kinergy.simulate("ur5e", "test-b", options, out=tmp_path / "api.csv")
    argv = ["simulate", "ur5e", "--trajectory", "test-b", "--mismatch", "realistic"]
    assert main([*argv, "--seed", "5", "--lag", "0.002", "--out", str(tmp_path / "c.csv")]) == 0
    assert (tmp_path / "api.csv").read_text() == (tmp_path / "c.csv").read_text()
    assert twin.settings.lag == 0.002 and twin.settings.current_step > 0  # realistic's steps


def _cli_list(argv: list[str], capsys: pytest.CaptureFixture[str]) -> Any:
    capsys.readouterr()
    assert main(argv) == 0
    return json.loads(capsys.readouterr().out)
