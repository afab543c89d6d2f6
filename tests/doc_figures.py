"""The figures the README and the documentation state, each tied to the command that produces it.

A :class:`Figure` is a sentence of a page with ``{name}`` where a figure stands, and a function
that runs kinergy's commands (their ``--json``, or their text where a page quotes a table) and
returns each figure as the page should print it. The sentence is found in the page with every
literal word kept and each ``{name}`` matching a number or a list of numbers (``0.963, 0.996
and 0.826``, ``0.976-0.998``); line breaks may fall anywhere. A :class:`Transcript` is a block a
page shows as a command's output: every line it shows must be a line the command prints, in order.

``tests/test_doc_figures.py`` checks every figure that takes under a minute or so (the real logs'
recipes, the demo); ``benchmarks/bench_doc_figures.py`` checks all of them, the optimisations
and placements that take minutes included, and with ``--write`` puts what the commands print
into the pages. A change that moves a figure fails until the page is updated.

Commands run in-process (:func:`kinergy.cli.main`) in one work folder, each once per session
(:class:`Runs` keeps their outputs); the real logs are read in place from ``../shared/datasets``
beside the repository, and a figure that needs them is skipped where they are absent.
"""

from __future__ import annotations

import contextlib
import io
import json
import re
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[1]
DATA = ROOT.parent / "shared" / "datasets"
UR10E = DATA / "ur10e-innopolis"
UR10E_COLUMNS = "timestamp,actual_q:6,actual_qd:6,actual_current:6,target_current:6,target_moment:6"
UR10E_RUNS = tuple(
    str(UR10E / "identification_data" / f"{name}.csv")
    for name in ("ur-20_02_19_15harm50sec", "ur-20_02_19_14harm50sec", "ur-20_02_12-50sec_12harm")
)
UR10E_HELD_OUT = str(UR10E / "validation_data" / "ur-20_01_17-ptp_10_points.csv")
UR3E = DATA / "ur3e-aurt" / "wave_currentData_100v_40a.csv"
UR5E_CALIBRATION = DATA / "ur5e-calibration" / "robot_calibration_summary.txt"
PANDA = DATA / "panda-gaz"
PROGRAMS = ROOT / "benchmarks" / "programs"

#: a figure: a signed number, thousands with commas, maybe an exponent (``5.963e-04``)
_NUMBER = r"[-+−]?\d[\d,]*(?:\.\d+)?(?:e[-+]\d+)?"
#: a placeholder: one figure or a list of them (``a, b and c``, ``a-b``)
_FIGURES = rf"{_NUMBER}(?:(?:,\s+|\s+and\s+|-|–){_NUMBER})*"


class Missing(Exception):
    """What a figure needs is not on this machine (the real logs): the figure is skipped."""


class Runs:
    """kinergy's commands run once each in ``folder``: their stdout, by their arguments."""

    def __init__(self, folder: Path):
        self.folder = folder
        self._out: dict[tuple[str, ...], str] = {}
        self._kept: dict[tuple[str, ...], Any] = {}

    def text(self, *args: str) -> str:
        """stdout of ``kinergy ARGS`` (in-process, in :attr:`folder`; a failure raises)."""
        if args not in self._out:
            from kinergy.cli import main

            out, err = io.StringIO(), io.StringIO()
            with (
                contextlib.chdir(self.folder),
                contextlib.redirect_stdout(out),
                contextlib.redirect_stderr(err),
            ):
                code = main(["--quiet", *args])
            if code != 0:
                raise AssertionError(f"kinergy {' '.join(args)} exited {code}: {err.getvalue()}")
            self._out[args] = out.getvalue()
        return self._out[args]

    def json(self, *args: str) -> Any:
        """``kinergy ARGS --json``, parsed."""
        return json.loads(self.text(*args, "--json"))

    def file(self, name: str, *args: str) -> str:
        """``name`` in :attr:`folder`, written by ``kinergy ARGS`` (run once)."""
        self.text(*args)
        return str(self.folder / name)

    def kept(self, key: tuple[str, ...], compute: Callable[[], Any]) -> Any:
        """``compute()`` (a benchmark's measurement, not a command), run once per ``key``."""
        if key not in self._kept:
            self._kept[key] = compute()
        return self._kept[key]


def need(*paths: Path) -> None:
    """Raise :class:`Missing` unless every path exists."""
    for path in (p for p in paths if not p.exists()):
        raise Missing(f"{path} is not on this machine")


@dataclass(frozen=True)
class Figure:
    """A sentence of ``page`` with figures, and where they come from.

    Attributes
    ----------
    page : str
        The page, relative to the repository.
    text : str
        The sentence as the page has it, ``{name}`` for each figure (whitespace matches any
        whitespace, so the page may wrap its lines anywhere).
    produce : callable
        ``produce(runs) -> {name: text}``: each figure as the page should print it.
    slow : bool
        Takes minutes: checked by the benchmark, not the test suite.
    script : str
        The benchmark script whose ``--check`` / ``--write`` checks it too (its stem,
        ``"bench_programs"``), or ``""``.

    A ``{name}`` that ``produce`` does not return matches any figure and is not compared (a
    timing, which depends on the host: its sentence names the command and the date).
    """

    page: str
    text: str
    produce: Callable[[Runs], dict[str, str]]
    slow: bool = False
    script: str = ""

    @property
    def name(self) -> str:
        words = re.sub(r"\{\w+\}", "#", self.text)
        return f"{self.page}: {words[:60]}"

    def pattern(self) -> re.Pattern[str]:
        parts = re.split(r"(\{\w+\})", self.text)
        regex = ""
        for part in parts:
            if re.fullmatch(r"\{\w+\}", part):
                regex += f"(?P<{part[1:-1]}>{_FIGURES})"
            else:
                regex += r"\s+".join(re.escape(word) for word in part.split(" "))
        return re.compile(regex)

    def found(self) -> re.Match[str]:
        """The sentence in its page (an AssertionError names the page when it is not there)."""
        text = (ROOT / self.page).read_text(encoding="utf-8")
        matches = list(self.pattern().finditer(text))
        assert len(matches) == 1, (
            f"{self.page}: {len(matches)} places read {self.text!r} (one expected)"
        )
        return matches[0]

    def differences(self, runs: Runs) -> list[str]:
        """Each figure the page states that the commands do not print, as one line."""
        match, produced = self.found(), self.produce(runs)
        return [
            f"{self.page}: says {match.group(key)!r} for {key} in {self.text!r}; "
            f"the commands give {value!r}"
            for key, value in produced.items()
            if " ".join(match.group(key).split()) != value
        ]

    def write(self, runs: Runs) -> bool:
        """Put the produced figures into the page; True when it changed."""
        path = ROOT / self.page
        text, match, produced = path.read_text(encoding="utf-8"), self.found(), self.produce(runs)
        moved = {k: v for k, v in produced.items() if " ".join(match.group(k).split()) != v}
        spans = sorted(((match.span(k), v) for k, v in moved.items()), reverse=True)
        new = text
        for (a, b), value in spans:
            new = new[:a] + value + new[b:]
        if new != text:
            path.write_text(new, encoding="utf-8")
        return new != text


@dataclass(frozen=True)
class Transcript:
    """A block of ``page`` showing a command's output: the lines after ``marker`` up to the
    closing fence, ``...`` lines standing for what is left out. Each line shown must be a line
    of ``produce(runs)``, in the same order."""

    page: str
    marker: str
    produce: Callable[[Runs], str]
    slow: bool = False
    script: str = ""

    @property
    def name(self) -> str:
        return f"{self.page}: {self.marker[:60]}"

    def _block(self) -> tuple[str, int, int]:
        text = (ROOT / self.page).read_text(encoding="utf-8")
        start = text.index(self.marker) + len(self.marker)
        start = text.index("\n", start) + 1
        return text, start, text.index("```", start)

    def differences(self, runs: Runs) -> list[str]:
        text, a, b = self._block()
        printed = [line.rstrip() for line in self.produce(runs).splitlines()]
        at = 0
        out = []
        for line in text[a:b].splitlines():
            if line.strip() in ("", "...") or line.startswith("$ "):
                continue
            try:
                at = printed.index(line.rstrip(), at) + 1
            except ValueError:
                head = line.split()[0] if line.split() else ""
                near = next((p for p in printed[at:] if p.split()[:1] == [head]), None)
                out.append(f"{self.page}: shows {line!r}; the command prints {near!r}")
        return out

    def write(self, runs: Runs) -> bool:
        """Each line shown replaced by the printed line with the same first word (the next
        one after the previous line's)."""
        path = ROOT / self.page
        text, a, b = self._block()
        printed = [line.rstrip() for line in self.produce(runs).splitlines()]
        at, lines = 0, []
        for line in text[a:b].splitlines():
            words = line.split()
            if line.strip() in ("", "...") or line.startswith("$ ") or not words:
                lines.append(line)
                continue
            hits = [i for i in range(at, len(printed)) if printed[i].split()[:1] == words[:1]]
            if hits:
                at = hits[0] + 1
                lines.append(printed[hits[0]])
            else:
                lines.append(line)
        new = text[:a] + "\n".join(lines) + "\n" + text[b:]
        if new != text:
            path.write_text(new, encoding="utf-8")
        return new != text


def check(
    figures: Sequence[Figure | Transcript | Table],
    runs: Runs,
    *,
    write: bool = False,
    say: Callable[[str], None] = print,
) -> int:
    """Each figure produced and compared with its page, one line each (``same``, ``differs``,
    ``skipped``, ``written``); with ``write`` the produced figures put into the pages. Returns
    how many differ."""
    import time

    differ = 0
    for figure in figures:
        start = time.perf_counter()
        try:
            lines = figure.differences(runs)
        except Missing as exc:
            say(f"skipped  {figure.name}: {exc}")
            continue
        took = time.perf_counter() - start
        if not lines:
            say(f"same     {figure.name} ({took:.0f} s)")
            continue
        differ += 1
        for line in lines:
            say(f"differs  {line}")
        if write and figure.write(runs):
            say(f"written  {figure.page}")
    return differ


@dataclass(frozen=True)
class Table:
    """A table of ``page`` a benchmark measures, whole: the lines from the one that starts with
    ``marker`` (its header) to the first blank line are ``produce(runs)``, line for line."""

    page: str
    marker: str
    produce: Callable[[Runs], str]
    slow: bool = True
    script: str = ""

    @property
    def name(self) -> str:
        return f"{self.page}: table {self.marker[:60]}"

    def _block(self) -> tuple[str, int, int]:
        text = (ROOT / self.page).read_text(encoding="utf-8")
        start = text.index("\n" + self.marker) + 1
        end = text.find("\n\n", start)
        return text, start, len(text) if end < 0 else end

    def differences(self, runs: Runs) -> list[str]:
        text, a, b = self._block()
        shown, made = text[a:b].splitlines(), self.produce(runs).splitlines()
        pairs = zip(shown + [""] * len(made), made + [""] * len(shown), strict=False)
        return [f"{self.page}: shows {x!r}; the benchmark gives {y!r}" for x, y in pairs if x != y]

    def write(self, runs: Runs) -> bool:
        text, a, b = self._block()
        new = text[:a] + self.produce(runs).rstrip("\n") + text[b:]
        if new != text:
            (ROOT / self.page).write_text(new, encoding="utf-8")
        return new != text


# ---------------------------------------------------------------------------------------------
# what the commands give, as the pages print it


def _r2s(rows: Sequence[dict[str, Any]], digits: int = 3) -> list[str]:
    return [f"{row['r2']:.{digits}f}" for row in rows]


def _listed(values: Sequence[str]) -> str:
    return ", ".join(values[:-1]) + " and " + values[-1]


def _span(values: Sequence[float], digits: int) -> str:
    return f"{min(values):.{digits}f}-{max(values):.{digits}f}"


def _thousands(x: float, digits: int = 0) -> str:
    return f"{x:,.{digits}f}"


def _ur10e_identify(runs: Runs) -> Any:
    need(UR10E)
    flags = ("--robot", "ur10e", "--columns", UR10E_COLUMNS, "--out", "ur10e-id.toml")
    return runs.json("identify", *UR10E_RUNS, *flags)


def _ur10e_model(runs: Runs) -> str:
    _ur10e_identify(runs)
    return str(runs.folder / "ur10e-id.toml")


def _ur10e_validate(runs: Runs) -> Any:
    return runs.json("validate", _ur10e_model(runs), UR10E_HELD_OUT, "--columns", UR10E_COLUMNS)


def _ur10e_energy(runs: Runs) -> Any:
    return runs.json("energy", _ur10e_model(runs), UR10E_HELD_OUT, "--columns", UR10E_COLUMNS)


def _ur10e_payload(runs: Runs, name: str, *flags: str) -> Any:
    log = str(UR10E / "identification_data" / f"{name}.csv")
    return runs.json(
        "identify",
        log,
        "--robot",
        _ur10e_model(runs),
        "--payload-only",
        *flags,
        "--columns",
        UR10E_COLUMNS,
        "--out",
        f"{name}.toml",
    )


def _payload_text(result: Any, name: str) -> dict[str, str]:
    p = result["payload"]
    return {name: f"{p['mass']:.3f}", f"{name}_std": f"{p['mass_std']:.3f}"}


def ur10e_validate(runs: Runs) -> dict[str, str]:
    r2 = _r2s(_ur10e_validate(runs)["current"])
    return {"r2": _listed(r2)}


def ur10e_validate_moving(runs: Runs) -> dict[str, str]:
    moving = _ur10e_validate(runs)["moving"]["current"]
    return {
        "five": _span([m["r2"] for m in moving[:5]], 3),
        "wrist3": f"{moving[5]['r2']:.3f}",
    }


def ur10e_fit(runs: Runs) -> dict[str, str]:
    return {"r2": _span([m["r2"] for m in _ur10e_identify(runs)["fit"]["current"]], 3)}


def ur10e_energy(runs: Runs) -> dict[str, str]:
    e = _ur10e_energy(runs)
    s = e["supply"]
    breakdown = {
        key: sum(j["breakdown"][key] for j in e["joints"]) for key in ("friction", "copper")
    }
    return {
        "drawn": f"{s['drawn']:.1f}",
        "duration": f"{e['duration']:.1f}",
        "mean": f"{s['drawn'] / e['duration']:.1f}",
        "motors": f"{s['motors']:.1f}",
        "standing": f"{s['standby']:.1f}",
        "power": f"{s['standby_power']:.1f}",
        "shunt": f"{s['shunt']:.1f}",
        "friction": f"{breakdown['friction']:.0f}",
        "copper": f"{breakdown['copper']:.0f}",
        "elec": f"{sum(j['e_elec'] for j in e['joints']):.0f}",
    }


def readme_ur10e(runs: Runs) -> dict[str, str]:
    e = _ur10e_energy(runs)
    s = e["supply"]
    return {
        **ur10e_validate(runs),
        "motors": _thousands(s["motors"]),
        "standing": _thousands(s["standby"]),
        "seconds": f"{e['duration']:.0f}",
        "power": f"{s['standby_power']:.1f}",
        **_payload_text(_ur10e_payload(runs, "ur-20_02_19_14harm50secLoad"), "payload"),
    }


def ur10e_payloads(runs: Runs) -> dict[str, str]:
    return {
        **_payload_text(_ur10e_payload(runs, "ur-20_02_19_14harm50secLoad"), "fourteen"),
        **_payload_text(_ur10e_payload(runs, "ur-20_02_19_15harm50secLoad", "--repair"), "fifteen"),
    }


def capabilities_ur10e(runs: Runs) -> dict[str, str]:
    r2 = [m["r2"] for m in _ur10e_validate(runs)["current"]]
    return {"five": f"{min(r2[:5]):.2f}-{max(r2[:5]):.3f}", "wrist3": f"{r2[5]:.2f}"}


def ur3e_fit(runs: Runs) -> dict[str, str]:
    need(UR3E)
    result = runs.json("identify", str(UR3E), "--robot", "ur3e", "--out", "ur3e-id.toml")
    return {"r2": f"{result['fit']['current'][1]['r2']:.3f}"}


def _calibration(runs: Runs) -> Any:
    need(UR5E_CALIBRATION)
    runs.file(
        "ur5e-cal.toml",
        "robot",
        "import-calibration",
        "ur5e",
        str(UR5E_CALIBRATION),
        "--out",
        "ur5e-cal.toml",
    )
    return runs.json(
        "robot", "import-calibration", "ur5e", str(UR5E_CALIBRATION), "--out", "ur5e-cal2.toml"
    )


def _worst(joint: Any, key: str) -> float:
    """The largest relative error of ``key`` against the calibration's friction over its points."""
    return max(abs(p[key] - p["friction"]) / abs(p["friction"]) for p in joint["points"])


def calibration_fit(runs: Runs) -> dict[str, str]:
    joints = _calibration(runs)["joints"]
    chosen = max(_worst(j, "friction_model") for j in joints)
    line = [_worst(j, "friction_contrast") for j in joints]
    return {
        "worst": f"{100 * chosen:.1f}",
        "line": f"{100 * min(line):.0f}-{100 * max(line):.0f}",
    }


def calibration_energy(runs: Runs) -> dict[str, str]:
    _calibration(runs)
    cal = runs.json("energy", "ur5e-cal.toml", "test-a")
    seed = runs.json("energy", "ur5e", "test-a")

    def joints(e: Any) -> float:
        return float(sum(j["e_elec"] for j in e["joints"]))

    return {
        "cal_motors": f"{cal['supply']['motors']:.0f}",
        "cal_joints": f"{joints(cal):.0f}",
        "seed_motors": f"{seed['supply']['motors']:.0f}",
        "seed_joints": f"{joints(seed):.0f}",
        "standing": f"{cal['supply']['standby']:.1f}",
        "seconds": f"{cal['duration']:.1f}",
        "cal_drawn": f"{cal['supply']['drawn']:.1f}",
        "seed_drawn": f"{seed['supply']['drawn']:.1f}",
    }


def _panda_split(runs: Runs) -> tuple[Any, Any]:
    """The Panda run identified on its first 70 % (by time) and validated on the last 30 %."""
    need(PANDA)
    t = [float(x) for x in (PANDA / "exciting_traj_time.txt").read_text().split()]
    cut = f"{t[0] + 0.7 * (t[-1] - t[0]):.4f}"
    flags = ("--robot", "panda", "--method", "full", "--target", "torque")
    model = runs.file(
        "panda-70.toml", "identify", str(PANDA), *flags, "--to", cut, "--out", "panda-70.toml"
    )
    return model, runs.json("validate", model, str(PANDA), "--from", cut)


def panda_held_out(runs: Runs) -> dict[str, str]:
    r2 = [m["r2"] for m in _panda_split(runs)[1]["joint_torque"]]
    return {"panda": f"{min(r2):.3f}-{max(r2):.4f}"}


def panda_held_out_joints(runs: Runs) -> dict[str, str]:
    r2 = [m["r2"] for m in _panda_split(runs)[1]["joint_torque"]]
    return {"r2": ", ".join(f"{x:.4f}" if x >= 0.999 else f"{x:.3f}" for x in r2)}


def _demo(runs: Runs, mismatch: str) -> str:
    return runs.text("demo", "--mismatch", mismatch, "--out", f"demo-{mismatch}")


def demo_efficiency(runs: Runs) -> dict[str, str]:
    text = _demo(runs, "realistic")
    table = text[text.index("(UR5e Table VIII), test A") :]
    overall = re.search(r"^overall\s+\S+\s+\S+\s+(\S+)\s+\S+\s+\S+\s+(\S+)", table, re.M)
    assert overall is not None, "the demo prints no Table VIII for test A"
    return {"ours": overall.group(1), "paper": overall.group(2)}


def demo_none_table(runs: Runs) -> str:
    return _demo(runs, "none")


def demo_none_b(runs: Runs) -> dict[str, str]:
    text = _demo(runs, "none")
    table = text[text.index("(UR5e Table VII), test B") :]
    r2 = [float(line.split()[4]) for line in table.splitlines()[2:8]]
    return {"r2": f"{min(r2):.3f}-{max(r2):.4f}"}


def test_count(runs: Runs) -> dict[str, str]:
    import subprocess
    import sys

    listed = subprocess.run(
        [sys.executable, "-m", "pytest", "--collect-only", "-q", "-p", "no:cacheprovider"],
        cwd=ROOT,
        capture_output=True,
        text=True,
        check=False,
    ).stdout
    count = sum(1 for line in listed.splitlines() if "::" in line)
    return {"tests": _thousands(round(count, -2))}


# ---------------------------------------------------------------------------------------------
# the slow ones: optimisations and placements (benchmarks/bench_doc_figures.py)


def _optimize(runs: Runs, program: str, *flags: str) -> Any:
    return runs.json("optimize", "ur5e", str(PROGRAMS / program), *flags)


def _saving(result: Any, energy: str = "e_supply") -> tuple[float, float, float]:
    """(before, after, saving %) of an optimisation's supply energy per cycle (``e_elec``: the
    motors' alone)."""
    before = result["program"][energy]
    after = result["optimized"][energy]
    return before, after, 100 * (1 - after / before)


def conveyor(runs: Runs) -> dict[str, str]:
    flags = ("--configurations", "free", "--tool-symmetry", "z")
    result = _optimize(runs, "ur5e_conveyor_to_tray.script", *flags)
    before, after, saving = _saving(result)
    m_before, m_after, m_saving = _saving(result, "e_elec")
    via = _optimize(runs, "ur5e_conveyor_to_tray.script", *flags, "--via", "free")
    return {
        "saving": f"{saving:.1f}",
        "before": f"{before:.1f}",
        "after": f"{after:.1f}",
        "motors": f"{m_saving:.1f}",
        "m_before": f"{m_before:.1f}",
        "m_after": f"{m_after:.1f}",
        "via": f"{_saving(via)[2]:.1f}",
        "via_motors": f"{_saving(via, 'e_elec')[2]:.1f}",
        "via_after": f"{_saving(via, 'e_elec')[1]:.1f}",
    }


_VIA = ("via", "via_motors", "via_after")


def place(runs: Runs) -> dict[str, str]:
    result = runs.json(
        "place",
        "ur10e",
        str(PROGRAMS / "ur10e_depalletising.script"),
        "--x",
        "-0.4:0.4",
        "--y",
        "-0.4:0.4",
        "--step",
        "0.2",
        "--tool-symmetry",
        "z4",
        "--configurations",
        "free",
        "--via",
        "free",
    )
    best, today = result["best"], result["today"]
    return {
        "x": f"{best['x']:.1f}",
        "y": f"{best['y']:.1f}",
        "saving": f"{100 * (1 - best['e_supply'] / today['e_supply']):.1f}",
    }


FIGURES: tuple[Figure | Transcript | Table, ...] = (
    # README
    Figure(
        "README.md",
        "Held-out current R² {r2} (wrist 3 stands still",
        ur10e_validate,
    ),
    Figure(
        "README.md",
        "the program's motors draw about {motors} J from the supply, and the arm's standing draw "
        "about {standing} J more over its {seconds} s (the built-in UR10e's {power} W, an "
        "estimate: these logs do not measure the supply); the 2.805 kg payload comes out "
        "{payload} ± {payload_std} kg.",
        lambda runs: {k: v for k, v in readme_ur10e(runs).items() if k != "r2"},
    ),
    Figure(
        "README.md",
        "UR10e held-out current R² {five} on five joints, {wrist3} on wrist 3; Panda held-out "
        "joint-torque R² {panda}",
        lambda runs: {**capabilities_ur10e(runs), **panda_held_out(runs)},
    ),
    Figure(
        "README.md",
        "UR5e twin: {ours} % overall efficiency against the paper's {paper} %",
        demo_efficiency,
    ),
    Figure(
        "README.md",
        "Friction fitted within {worst} % of every calibration point (Coulomb + viscous: {line} %).",
        calibration_fit,
    ),
    # recipes
    Figure(
        "docs/recipes.md",
        "and the fit on the three runs (current R² {r2})",
        ur10e_fit,
    ),
    Figure(
        "docs/recipes.md",
        "The current R² per joint came out {r2}: wrist 3 stands",
        ur10e_validate,
    ),
    Figure(
        "docs/recipes.md",
        "gives {five} on joints 1-5 and {wrist3} on wrist 3.",
        ur10e_validate_moving,
    ),
    Figure(
        "docs/recipes.md",
        "It printed {drawn} J drawn over {duration} s (mean {mean} W): the motors {motors} J and "
        "the standing draw {standing} J (the built-in UR10e's {power} W, an estimate: these logs "
        "do not measure the supply), with {shunt} J of braking burnt in the shunt; friction "
        "{friction} J and copper {copper} J of the joints' {elec} J",
        ur10e_energy,
    ),
    Figure(
        "docs/recipes.md",
        "They gave {fourteen} ± {fourteen_std} kg and {fifteen} ± {fifteen_std} kg",
        ur10e_payloads,
    ),
    Figure(
        "docs/recipes.md",
        "so only it is identified (current R² {r2})",
        ur3e_fit,
    ),
    Figure(
        "docs/recipes.md",
        "Every joint's friction came out within {worst} % of the calibration at every speed",
        lambda runs: {"worst": calibration_fit(runs)["worst"]},
    ),
    Figure(
        "docs/recipes.md",
        "where Coulomb + viscous is {line} % off at its worst point.",
        lambda runs: {"line": calibration_fit(runs)["line"]},
    ),
    Figure(
        "docs/recipes.md",
        "the built-in test A's motors draw {cal_motors} J from the supply ({cal_joints} J at the "
        "joints), against {seed_motors} J ({seed_joints} J) with the built-in `ur5e`'s seed "
        "friction",
        lambda runs: {
            k: v
            for k, v in calibration_energy(runs).items()
            if k in ("cal_motors", "cal_joints", "seed_motors", "seed_joints")
        },
    ),
    Figure(
        "docs/recipes.md",
        "The arm's standing draw ({standing} J over the {seconds} s) comes on top of either: "
        "{cal_drawn} J and {seed_drawn} J drawn.",
        lambda runs: {
            k: v
            for k, v in calibration_energy(runs).items()
            if k in ("standing", "seconds", "cal_drawn", "seed_drawn")
        },
    ),
    Figure(
        "docs/recipes.md",
        "Joint-torque R² {r2} on the held-out 30 %",
        panda_held_out_joints,
    ),
    # getting started
    Transcript(
        "docs/getting-started.md",
        "$ kinergy demo --mismatch none --out kinergy-demo",
        demo_none_table,
    ),
    Figure(
        "docs/getting-started.md",
        "the unseen test B's currents are predicted with R² {r2}, their RMS error",
        demo_none_b,
    ),
    Figure(
        "docs/getting-started.md",
        "runs the tests: about {tests} tests",
        test_count,
    ),
    # the optimisations: minutes each
    Figure(
        "docs/recipes.md",
        "The first command printed a saving of {saving} % of the supply energy per cycle "
        "({before} J to {after} J: the motors and the UR5e's standing draw of 34.4 W over the "
        "8.39 s cycle, which no lever changes) and {motors} % of the motors' energy ({m_before} J "
        "to {m_after} J); with `--via free` as well,",
        lambda runs: {k: v for k, v in conveyor(runs).items() if k not in _VIA},
        slow=True,
    ),
    Figure(
        "docs/recipes.md",
        "passes every cycle), {via} % and {via_motors} % ({via_after} J).",
        lambda runs: {k: v for k, v in conveyor(runs).items() if k in _VIA},
        slow=True,
    ),
    Figure(
        "docs/recipes.md",
        "the best of the 25 placements ({x} m along x and {y} m along y) draws {saving} % less",
        place,
        slow=True,
    ),
)
