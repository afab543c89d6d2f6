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
    result = kinergy.identify(FOURIER, robot, columns=SPEC, out=tmp_path / "api.toml")
    argv = ["identify", *map(str, FOURIER), "--robot", "ur10e", "--columns", SPEC]
    cli = _cli([*argv, "--out", str(tmp_path / "cli.toml"), "--json"], capsys)
    _same(_plain(result.to_dict()), cli)
    model = kinergy.load_robot(tmp_path / "api.toml")
    assert model.identified is not None and len(model.identified.inputs) == 2

    report = kinergy.validate(model, [HELD_OUT], columns=SPEC)
    cli = _cli(
        ["validate", str(tmp_path / "api.toml"), str(HELD_OUT), "--columns", SPEC, "--json"], capsys
    )
    cli["inputs"] = [i for i in cli["inputs"] if not i["path"].endswith(".toml")]  # the model file
    _same(_plain(kinergy.jsonable.to_jsonable(report)), cli)

    energy = kinergy.energy(model, HELD_OUT, columns=SPEC)
    cli = _cli(
        ["energy", str(tmp_path / "api.toml"), str(HELD_OUT), "--columns", SPEC, "--json"], capsys
    )
    cli["inputs"] = [i for i in cli["inputs"] if not i["path"].endswith(".toml")]
    _same(_plain(energy.to_dict()), cli)


def test_read_log_checks_with_a_robot_and_simulate_writes_the_twin() -> None:
    import kinergy.identification.sequential  # a sub-package never shadows the function

    assert callable(kinergy.identify) and callable(kinergy.simulate)
    log = kinergy.simulate("ur5e", "test-b", mismatch="realistic", seed=2)
    assert len(log) > 1000 and "actual_current" in log
    with pytest.raises(kinergy.KinergyError, match="trajectory must be"):
        kinergy.simulate("ur5e", "test-c")
    motion_energy = kinergy.energy(
        "ur5e", kinergy.movej([[0] * 6, [1, -1, 1, 0, 1, 0]], speed=1.0, acceleration=2.0, dt=0.002)
    )
    assert motion_energy.total_e_elec > 0 and motion_energy.t.size > 100


@pytest.mark.skipif(not UR10E.exists(), reason="shared datasets not available")
def test_read_log_through_the_checks() -> None:
    log = kinergy.read_log(HELD_OUT, columns=SPEC, robot="ur10e")
    assert log["actual_q"].shape == (len(log), 6)
    swapped = SPEC.replace("actual_q:6,actual_qd:6", "actual_qd:6,actual_q:6")
    with pytest.raises(kinergy.KinergyError, match="speeds check failed"):
        kinergy.read_log(HELD_OUT, columns=swapped, robot="ur10e")
    assert len(kinergy.read_log(HELD_OUT, columns=swapped)) == len(log)  # unchecked without a robot


def test_optimize_program_equals_the_command(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """``kinergy.optimize_program`` on a URScript program and on a task gives the command's JSON;
    a lever's name is parsed (and a wrong one refused) as the flag is."""
    small = Path(__file__).parent / "programs" / "small.script"
    run = kinergy.optimize_program("ur5e", small, tool_symmetry="z", urscript=tmp_path / "a.script")
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
    task = kinergy.optimize_program("ur5e", "test-a", blends=False)
    cli = _cli(["optimize", "ur5e", "test-a", "--no-blends", "--json"], capsys)
    cli.pop("inputs")
    api = _plain(task.to_dict())
    api["written"], cli["written"] = [], []
    _same(api, cli)
    with pytest.raises(kinergy.KinergyError, match="tool symmetry: expected one of none, z"):
        kinergy.optimize_program("ur5e", small, tool_symmetry="z3")


def test_a_wrong_option_is_one_kinergy_error_naming_it() -> None:
    with pytest.raises(kinergy.KinergyError, match=r"method='payload': not one of sequential"):
        kinergy.identify(["x.csv"], "ur5e", method="payload")
    with pytest.raises(kinergy.KinergyError, match=r"target='voltage': not one of"):
        kinergy.identify(["x.csv"], "ur5e", method="full", target="voltage")
    with pytest.raises(kinergy.KinergyError, match=r"via points: expected keep or free"):
        kinergy.optimize_program("ur5e", "test-a", via="open")


def test_a_task_and_a_urscript_program_take_the_same_options(
    capsys: pytest.CaptureFixture[str],
) -> None:
    """A task is a movej program: the levers and the Pareto front are taken for either kind (no
    option is refused for the kind of program); a plot without a front is refused."""
    small = str(Path(__file__).parent / "programs" / "small.script")
    assert main(["optimize", "ur5e", small, "--pareto-points", "0", "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["pareto"] == []
    assert main(["optimize", "ur5e", "test-b", "--plot", "p.png", "--pareto-points", "0"]) == 1
    err = capsys.readouterr().err
    assert err.startswith("kinergy: error: --plot: needs a Pareto front") and err.count("\n") == 1


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
    api = kinergy.energy("ur5e", log, repair=True)
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
