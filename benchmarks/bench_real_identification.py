"""Issue 12's acceptance figures on the real logs in ../shared/datasets (not a timed test).

Every figure comes from the command line, as a user would get it (``kinergy identify``,
``kinergy validate --json``), with the exit status checked:

- ``ur10e``: identify on the unloaded UR10e Fourier runs (``*harm*.csv`` without ``Load``) by the
  sequential method, the full method (default target) and the full method against currents;
  held-out current R^2 per joint on ``ptp_10_points`` (pooled, moving samples apart), and where
  wrists 2 and 3 lose it (standstill);
- ``payload``: the payload of each loaded run (``*Load.csv``, 2.805 kg) on the sequential model:
  mass error and the two runs' centre-of-mass agreement, ``|c1 - c2| <= 2 sqrt(s1^2 + s2^2)``;
- ``panda``: the Panda run (converted to the ``record.py`` layout with measured joint torques as
  ``actual_joint_torque_k``), identified by ``--method full --target torque`` on the first 70 %
  of the time and validated on the last 30 %;
- ``sweep``: every log in the datasets by every method: exit status, and for each model written
  whether any link mass, link inertia, rotor inertia or friction coefficient is unphysical;
- ``bad``: an unexciting log, a log of one joint moving, a log shorter than a second.

    python benchmarks/bench_real_identification.py [ur10e payload panda sweep bad] [--out DIR]
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

DATA = Path(__file__).resolve().parents[2] / "shared" / "datasets"
UR10E = DATA / "ur10e-innopolis"
UR10E_COLUMNS = "timestamp,actual_q:6,actual_qd:6,actual_current:6,target_current:6,target_moment:6"
UR10E_SHORT = "timestamp,actual_q:6,actual_qd:6,actual_current:6"
HELD_OUT = UR10E / "validation_data" / "ur-20_01_17-ptp_10_points.csv"
PAYLOAD_MASS = 2.805


def ur10e_logs(paths: list[Path], *, repair: bool = False) -> list:
    """The prepared segments of UR10e logs (``UR10E_COLUMNS``), read through the checks."""
    from kinergy.io.columns import parse_columns
    from kinergy.logs.reading import LogReading
    from kinergy.model import load_robot
    from kinergy.workflows.logs import prepared_logs

    reading = LogReading(columns=tuple(parse_columns(UR10E_COLUMNS, 6)), repair=repair)
    return prepared_logs(paths, load_robot("ur10e"), reading)[0]


def kinergy(*args: str) -> tuple[int, str, str]:
    """Run the command line; exit status, stdout and stderr."""
    done = subprocess.run(
        [sys.executable, "-c", "from kinergy.cli import run; run()", *map(str, args)],
        capture_output=True,
        text=True,
        check=False,
    )
    return done.returncode, done.stdout, done.stderr


def unloaded_runs() -> list[Path]:
    return sorted(
        p for p in (UR10E / "identification_data").glob("*harm*.csv") if "Load" not in p.name
    )


def held_out_r2(model: Path, log: Path, columns: str | None, key: str) -> dict[str, list]:
    """Pooled and moving-only R^2 per joint of signal ``key`` on ``log``."""
    extra = ["--columns", columns] if columns else []
    rc, out, err = kinergy("validate", model, log, *extra, "--json")
    assert rc == 0, err
    report = json.loads(out)
    return {
        "pooled": [m["r2"] for m in report[key]],
        "moving": [m["r2"] for m in report["moving"][key]] if report["moving"] else None,
    }


def bench_ur10e(out: Path) -> dict:
    results = {}
    runs = unloaded_runs()
    for label, options in (
        ("sequential", ["--method", "sequential"]),
        ("full", ["--method", "full"]),
        ("full --target current", ["--method", "full", "--target", "current"]),
    ):
        model = out / f"ur10e_{label.replace(' ', '_').replace('--', '')}.toml"
        rc, _, err = kinergy(
            "identify", "--robot", "ur10e", "--columns", UR10E_COLUMNS, "--repair",
            *options, "--out", model, *runs,
        )  # fmt: skip
        assert rc == 0, err
        results[label] = held_out_r2(model, HELD_OUT, UR10E_COLUMNS, "current")
        print(f"ur10e {label}: held-out current R^2 {np.round(results[label]['pooled'], 4)}")
        print(f"    moving samples only {np.round(results[label]['moving'], 4)}")
    results["standstill"] = standstill_evidence(out / "ur10e_sequential.toml")
    return results


def _stops(moving: np.ndarray, min_len: int = 50) -> list[tuple[int, int]]:
    """(start, stop) of every run of ``moving == False`` at least ``min_len`` samples long."""
    edges = np.flatnonzero(np.diff(np.concatenate([[0], (~moving).astype(int), [0]])))
    return [(a, b) for a, b in zip(edges[::2], edges[1::2], strict=True) if b - a >= min_len]


def standstill_evidence(model: Path) -> dict:
    """Why wrists 2 and 3 lose R^2 on ``ptp_10_points``: per wrist, the share of samples where
    it stands still (|qd| < 0.02 rad/s), the share of the held-out squared current error that
    falls there, R^2 while it moves, and the ceiling set by the current's wander within each
    standstill around its own mean (no model predicting a steady current at rest can explain
    it); then what sets the level at rest (:func:`rest_level_evidence`)."""
    from kinergy.identification.result import predict
    from kinergy.model import load_robot

    data = ur10e_logs([HELD_OUT])[0]
    assert data.current is not None
    predicted = predict(load_robot(str(model)), data).current
    assert predicted is not None
    out = {}
    for j in (4, 5):
        moving = np.abs(data.qd[:, j]) >= 0.02
        y, e = data.current[:, j], data.current[:, j] - predicted[:, j]
        total = float(np.sum((y - y.mean()) ** 2))
        within = sum(float(np.sum((y[a:b] - y[a:b].mean()) ** 2)) for a, b in _stops(moving, 1))
        ym = y[moving]
        row = {
            "still": float(np.mean(~moving)),
            "error_share_still": float(np.sum(e[~moving] ** 2) / np.sum(e**2)),
            "r2_moving": 1.0 - float(np.sum(e[moving] ** 2) / np.sum((ym - ym.mean()) ** 2)),
            "ceiling": 1.0 - within / total,
        }
        out[f"joint {j + 1}"] = row
        print(
            f"joint {j + 1} on ptp_10_points: still {row['still']:.0%} of the samples, "
            f"{row['error_share_still']:.0%} of the squared current error falls there; "
            f"R^2 while it moves {row['r2_moving']:.3f}; wander within standstills caps R^2 "
            f"at {row['ceiling']:.3f}"
        )
    out["rest level"] = rest_level_evidence(model)
    return out


def rest_level_evidence(model: Path) -> dict:
    """What the wrists' current at rest follows. (1) Every stop after motion in the unloaded
    Fourier runs: the current the model leaves unexplained (friction off) over the joint's
    Coulomb level, signed by the direction of the last motion (1 = all of the friction of the
    last direction held). (2) The same pose held twice: p1 and p10 (static holds) against the
    first and last stop of ptp_10_points at that pose. (3) The controller's own model
    (``target_moment``) during the wrist-3 stops of ptp_10_points."""
    import dataclasses

    from kinergy.identification.result import predict
    from kinergy.model import Friction, load_robot

    robot = load_robot(str(model))
    bare = robot.with_joints(
        [dataclasses.replace(j, drive=dataclasses.replace(j.drive, friction=Friction("none", {})))
         for j in robot.joints]
    )  # fmt: skip
    fractions: dict[int, list[float]] = {3: [], 4: [], 5: []}
    for data in ur10e_logs(unloaded_runs()):
        load = predict(bare, data).current
        for j, found in fractions.items():
            coulomb = robot.joints[j].drive.friction.params["coulomb_direct"]
            level = coulomb / robot.joints[j].drive.torque_constant
            for a, b in _stops(np.abs(data.qd[:, j]) >= 0.005):
                if a >= 20:
                    last = np.sign(data.qd[a - 10 : a, j].mean())
                    found.append(last * float(np.mean(data.current[a:b, j] - load[a:b, j])) / level)
    out = {}
    for j, f in fractions.items():
        h = np.array(f)
        out[f"joint {j + 1}"] = {"stops": h.size, "same sign": float(np.mean(h > 0)),
                                 "median": float(np.median(h)), "spread": float(np.std(h))}  # fmt: skip
        print(
            f"joint {j + 1}: {h.size} stops in the Fourier runs; the current at rest keeps the "
            f"last direction's friction sign in {np.mean(h > 0):.0%}, fraction held median "
            f"{np.median(h):.2f}, spread (sd) {np.std(h):.2f}"
        )
    out["same pose twice"] = _same_pose_twice()
    return out


def _same_pose_twice() -> dict:
    """The wrists' mean current in the static holds p1 and p10 against ptp_10_points's first
    and last stop at the same pose, and the controller's ``target_moment`` in those stops."""
    ptp = np.loadtxt(HELD_OUT, delimiter=",")
    still = np.all(np.abs(ptp[:, 7:13]) < 0.005, axis=1)
    first, last = _stops(~still)[0], _stops(~still)[-1]
    out = {}
    for name, (a, b) in (("p1", first), ("p10", last)):
        hold = np.loadtxt(UR10E / "validation_data" / f"ur-20_01_17-{name}.csv", delimiter=",")
        mine, theirs = hold[:, 16:19].mean(axis=0), ptp[a:b, 16:19].mean(axis=0)
        moment = np.abs(ptp[a:b, 28:31]).max(axis=0)
        out[name] = {"hold": mine.tolist(), "ptp": theirs.tolist()}
        print(
            f"{name} pose held twice: wrist currents {np.round(mine, 3)} A (static log) against "
            f"{np.round(theirs, 3)} A (ptp_10_points stop); the controller's target_moment "
            f"there stays below {np.round(moment, 3)} N m"
        )
    return out


def bench_payload(out: Path) -> dict:
    model = out / "ur10e_sequential.toml"
    if not model.exists():
        rc, _, err = kinergy(
            "identify", "--robot", "ur10e", "--columns", UR10E_COLUMNS, "--repair",
            "--out", model, *unloaded_runs(),
        )  # fmt: skip
        assert rc == 0, err
    runs = sorted((UR10E / "identification_data").glob("*Load.csv"))
    found = []
    for run in runs:
        rc, text, err = kinergy(
            "identify", "--payload-only", "--robot", model, "--columns", UR10E_COLUMNS,
            "--repair", "--json", "--out", out / f"payload_{run.stem}.toml", run,
        )  # fmt: skip
        assert rc == 0, err
        found.append(json.loads(text)["payload"])
    for p, run in zip(found, runs, strict=True):
        err = p["mass"] / PAYLOAD_MASS - 1
        print(
            f"{run.name}: mass {p['mass']:.3f} +- {p['mass_std']:.3f} kg ({err:+.1%}), "
            f"com {np.round(p['com'], 4)} +- {np.round(p['com_std'], 4)} m"
        )
    c1, c2 = (np.array(p["com"]) for p in found)
    s1, s2 = (np.array(p["com_std"]) for p in found)
    agree = np.abs(c1 - c2) <= 2 * np.hypot(s1, s2)
    r1, r2 = np.hypot(c1[0], c1[1]), np.hypot(c2[0], c2[1])
    turn = np.degrees(np.arctan2(c2[1], c2[0]) - np.arctan2(c1[1], c1[0])) % 360
    print(f"centres of mass agree within 2 sigma per axis: {agree.tolist()}")
    print(
        f"distance from the flange axis {r1:.3f} and {r2:.3f} m; the second run's centre of mass "
        f"is turned {turn:.0f} deg about the flange axis from the first's"
    )
    q6 = [float(np.mean(np.loadtxt(r, delimiter=",", usecols=6, max_rows=5000))) for r in runs]
    print(
        f"mean wrist-3 angle of the two loaded runs {q6[0]:.2f} and {q6[1]:.2f} rad "
        f"(differ by {abs(q6[1] - q6[0]):.2f}, not pi): no frame turned half a turn"
    )
    pairs = {run.name: pair_difference(model, run) for run in runs}
    return {"payloads": found, "agree": agree.tolist(), "radius": [r1, r2], "turn_deg": turn,
            "wrist3_mean": q6, "pairs": pairs}  # fmt: skip


def pair_difference(model: Path, loaded: Path) -> dict:
    """The payload from a loaded run minus the unloaded run of the same trajectory (same day):
    the unloaded run's currents, aligned in time on the joint angles, replace the model's
    prediction, so only the torque constants and the kinematics enter. A point mass is fitted
    to the difference (jackknife errors, as ``identify --payload-only``), its R^2 per joint is
    printed, and again with wrist 3's angle negated (a frame turning the wrong way with q6
    would fit better that way)."""
    from kinergy.drives.electrics import torque_constants
    from kinergy.drives.transmission import joint_torque
    from kinergy.dynamics.regressor import regressor
    from kinergy.identification.payload import _com, block_std
    from kinergy.linalg import scaled_lstsq
    from kinergy.model import load_robot

    robot = load_robot(str(model)).with_payload(None)
    bare = loaded.with_name(loaded.name.replace("Load", ""))
    on, off = (
        max(ur10e_logs([log], repair=True), key=len) for log in (loaded, bare)
    )  # the longest segment of each
    t_on, t_off = on.t - on.t[0], off.t - off.t[0]
    lags = np.arange(-5.0, 5.0, 0.002)
    miss = [np.mean((np.interp(t_on + g, t_off, off.q[:, 0]) - on.q[:, 0]) ** 2) for g in lags]
    lag = float(lags[int(np.argmin(miss))])
    keep = (t_on + lag > 0) & (t_on + lag < t_off[-1])
    current = np.column_stack([np.interp(t_on + lag, t_off, off.current[:, k]) for k in range(6)])
    tau = joint_torque(robot, (on.current - current)[keep] * torque_constants(robot)).reshape(-1)
    result = {}
    for label, sign in (("as modelled", 1.0), ("wrist 3 negated", -1.0)):
        flip = np.array([1, 1, 1, 1, 1, sign])
        q, qd, qdd = (x[keep] * flip for x in (on.q, on.qd, on.qdd))
        a = regressor(robot, q, qd, qdd)[:, :, 50:54].reshape(-1, 4)
        x, std, _ = scaled_lstsq(a, tau)
        std = np.maximum(std, block_std(a, tau, 6))
        resid = (tau - a @ x).reshape(-1, 6)
        y = tau.reshape(-1, 6)
        r2 = 1.0 - np.sum(resid**2, axis=0) / np.sum((y - y.mean(axis=0)) ** 2, axis=0)
        com = _com(robot, x)
        result[label] = {"mass": float(x[0]), "mass_std": float(std[0]), "com": com.tolist(),
                         "com_std": (std[1:4] / x[0]).tolist(), "r2": r2.tolist()}  # fmt: skip
        print(
            f"{loaded.name} minus {bare.name} (lag {lag:.2f} s), {label}: mass {x[0]:.3f} +- "
            f"{std[0]:.3f} kg, com {np.round(com, 3)} +- {np.round(std[1:4] / x[0], 3)} m, "
            f"R^2 per joint {np.round(r2, 3)}"
        )
    return result


def panda_log(folder: Path) -> tuple[Path, Path]:
    """The Panda run in the ``record.py`` layout (measured torques as ``actual_joint_torque_k``),
    split by time into the first 70 % (identification) and the last 30 % (held out)."""
    src = DATA / "panda-gaz"
    t = np.loadtxt(src / "exciting_traj_time.txt")
    q, qd, tau = (
        np.loadtxt(src / f"exciting_traj_{name}.txt").reshape(-1, 7)
        for name in ("positions", "velocity", "torques")
    )
    header = " ".join(
        ["timestamp"]
        + [
            f"{name}_{k}"
            for name in ("actual_q", "actual_qd", "actual_joint_torque")
            for k in range(7)
        ]
    )
    table = np.column_stack([t, q, qd, tau])
    cut = int(0.7 * len(t))
    paths = folder / "panda_identify.csv", folder / "panda_held_out.csv"
    for path, rows in zip(paths, (table[:cut], table[cut:]), strict=True):
        np.savetxt(path, rows, header=header, comments="", fmt="%.9g")
    return paths


def bench_panda(out: Path) -> dict:
    train, test = panda_log(out)
    model = out / "panda_full.toml"
    rc, _, err = kinergy(
        "identify", "--robot", "panda", "--method", "full", "--target", "torque",
        "--out", model, train,
    )  # fmt: skip
    assert rc == 0, err
    r2 = held_out_r2(model, test, None, "joint_torque")
    print(f"panda held-out joint-torque R^2 {np.round(r2['pooled'], 4)}")
    return r2


def physical_problems(model: Path) -> list[str]:
    """What is unphysical in a written model: link masses, link inertias, rotor inertias,
    friction coefficients."""
    from kinergy.model import load_robot
    from kinergy.model.robot import inertia_matrix

    robot = load_robot(str(model))
    problems = []
    for j in robot.joints:
        if j.link.mass < 0:
            problems.append(f"{j.name}: mass {j.link.mass:g}")
        eig = np.linalg.eigvalsh(inertia_matrix(j.link.inertia))
        if eig.min() < 0 or eig.max() > eig.sum() - eig.max() + 1e-12 * eig.max():
            problems.append(f"{j.name}: link inertia not physical (principal moments {eig})")
        if j.drive.rotor_inertia < 0:
            problems.append(f"{j.name}: rotor inertia {j.drive.rotor_inertia:g}")
        for name, value in j.drive.friction.params.items():
            if isinstance(value, float) and value < 0:
                problems.append(f"{j.name}: friction {name} {value:g}")
    return problems


def every_log() -> list[tuple[Path, str, str | None]]:
    """(log, robot, columns) for every log of the datasets that carries joint signals."""
    logs: list[tuple[Path, str, str | None]] = []
    for p in sorted(UR10E.rglob("*.csv")):
        with p.open() as f:  # the 2019 runs log time, positions, speeds and currents only
            fields = len(f.readline().split(","))
        logs.append((p, "ur10e", UR10E_COLUMNS if fields == 31 else UR10E_SHORT))
    logs += [(p, "ur3e", None) for p in sorted((DATA / "ur3e-aurt").glob("wave_*.csv"))]
    return logs


def _refusal(err: str) -> list[str]:
    """The lines of a refusal on stderr, without the reader's notes."""
    return [ln for ln in err.strip().splitlines() if ln and not ln.startswith("kinergy: note")]


def bench_sweep(out: Path) -> dict:
    start = time.perf_counter()
    rows = []
    panda = [(p, "panda", None) for p in panda_log(out)]
    for log, robot, columns in every_log() + panda:
        for method in ("sequential", "full", "nursing"):
            model = out / f"sweep_{log.stem}_{method}.toml"
            model.unlink(missing_ok=True)
            extra = ["--columns", columns] if columns else []
            rc, _, err = kinergy(
                "identify", "--robot", robot, "--method", method, "--repair", *extra,
                "--out", model, log,
            )  # fmt: skip
            problems = physical_problems(model) if rc == 0 else []
            said = _refusal(err) if rc != 0 else []
            last = said[-1] if said else ""
            rows.append((log.name, method, rc, problems, last, len(said)))
            print(f"{log.name:40s} {method:10s} exit {rc} {problems or ''} {last[:110]}")
    bad = [r for r in rows if r[2] == 0 and r[3]]
    refused = [r for r in rows if r[2] != 0]
    one_line = sum(r[5] == 1 for r in refused)
    wall = time.perf_counter() - start
    print(
        f"{len(rows)} runs, {len(rows) - len(refused)} wrote a model, {len(refused)} refused "
        f"({one_line} in one line), {len(bad)} unphysical with exit 0; wall time {wall:.0f} s"
    )
    return {"runs": len(rows), "written": len(rows) - len(refused), "refused": len(refused),
            "one_line": one_line, "unphysical": bad, "wall_s": wall}  # fmt: skip


def bench_bad(out: Path) -> dict:
    """Three bad logs: the UR10e ptp program's first sample held for 20 s, the same with joint 1
    swinging (the other signals frozen), and 0.8 s of a Fourier run."""
    raw = np.loadtxt(HELD_OUT, delimiter=",")
    q0 = raw[0, 1:7]
    t = np.arange(0, 20.0, 0.01)
    cases = {}
    still = np.tile(raw[0], (t.size, 1))
    still[:, 0] = t
    still[:, 7:13] = 0.0
    cases["unexciting"] = still
    one = still.copy()
    one[:, 1] = q0[0] + 0.5 * np.sin(t)
    one[:, 7] = 0.5 * np.cos(t)
    cases["one joint moving"] = one
    fourier = UR10E / "identification_data" / "ur-20_02_12-50sec_12harm.csv"
    cases["shorter than a second"] = np.loadtxt(fourier, delimiter=",")[1000:1080]
    results = {}
    for name, table in cases.items():
        path = out / f"bad_{name.replace(' ', '_')}.csv"
        np.savetxt(path, table, delimiter=",", fmt="%.9g")
        for method in ("sequential", "full"):
            model = out / f"bad_{method}.toml"
            model.unlink(missing_ok=True)
            rc, text, err = kinergy(
                "identify", "--robot", "ur10e", "--method", method, "--columns", UR10E_COLUMNS,
                "--out", model, path, "--json",
            )  # fmt: skip
            if rc == 0:
                joints = json.loads(text)["joints"]
                kept = sorted({f for j in joints for f in j.get("flags", {}).values()})
                said = f"model written, flags {kept}"
            else:
                said = err.strip()
            results[f"{name} ({method})"] = (rc, model.exists(), said)
            print(
                f"{name} ({method}): exit {rc}, model {'written' if model.exists() else 'not written'}: {said[:160]}"
            )
    return results


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parts = {"ur10e": bench_ur10e, "payload": bench_payload, "panda": bench_panda,
             "sweep": bench_sweep, "bad": bench_bad}  # fmt: skip
    parser.add_argument("parts", nargs="*", default=list(parts), choices=list(parts))
    parser.add_argument("--out", type=Path, default=None, help="keep the models here")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        out = args.out or Path(tmp)
        out.mkdir(parents=True, exist_ok=True)
        for part in args.parts:
            print(f"== {part}")
            parts[part](out)


if __name__ == "__main__":
    main()
