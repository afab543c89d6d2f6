"""``kinergy nursing``: the coupled-drive nursing arm's identification, run on the digital twin.

The nursing doc's procedure (sections 4.1-4.2; :mod:`kinergy.identify.nursing`) end to end:

1. for every joint, the constant-speed back-and-forth friction runs, simulated by the twin
   (:func:`kinergy.simulate.simulate`) with its current noise (``--noise``, the twin's default
   :class:`~kinergy.simulate.TwinSettings`) or without (``--exact``); currents to joint torques
   by eq 21 and the robot's coupling; friction as the odd part (eq 20); Makkar's model (eq 13)
   fitted by particle swarm optimisation and by least squares, next to the twin's own curve (the
   robot file's motor-side Makkar converted to the joint side, ``gamma1, gamma4 * k n``, rates
   ``* n``, ``gamma6 * k n^2``; k = 2 motors of n = 3060 on the nursing arm) and the doc's
   Table 4 and R^2 (0.927 pitch, 0.931 rotation);
2. the excitation of Table 6 (eq 22), ten 10 s periods on the twin, currents filtered at 15 Hz
   and averaged over the periods (eq 24), joint torques less the identified friction and drive
   inertia (eq 25), ridge regression of the minimal parameter set on a 70/30 split in time, and
   the per-joint RMSE on the 30 % (eq 26) next to the doc's Table 8.
"""

from __future__ import annotations

import json
import time
from collections.abc import Callable
from typing import Any

import click
import numpy as np

from kinergy.cli.common import table
from kinergy.errors import KinergyError
from kinergy.model import Robot, load_robot

__all__ = ["nursing", "nursing_study"]


def _twin_log(robot: Robot, name: str, motion: Any, settings: Any) -> Any:
    from kinergy.identify.preprocess import prepare
    from kinergy.simulate import simulate

    return prepare(simulate(robot, motion, settings, name=name), robot.n)


def nursing_study(
    robot: Robot,
    *,
    noise: bool = True,
    seed: int = 0,
    progress: Callable[[str], None] | None = None,
) -> dict[str, Any]:
    """Run the nursing doc's identification on ``robot``'s twin (module docstring).

    Parameters
    ----------
    robot : Robot
        The twin's model (6 joints, for Table 6's excitation).
    noise : bool
        The twin's default lag and noise (``TwinSettings(seed=...)``) or none.
    seed : int
        Seed of the twin's noise (log k uses ``seed + k``) and of the swarm.
    progress : callable, optional
        Called with a line of text at each stage.

    Returns
    -------
    dict
        JSON-ready: ``robot``, ``noise``, ``seed``, ``friction`` (per joint: ``kind``, speed
        ``levels`` and range, ``pso`` and ``lsq`` fits with ``gamma``, ``r2`` (levels),
        ``r2_samples``, ``twin`` (the model's joint-side gamma and the fits' largest relative
        parameter error, or None), ``doc`` (Table 4 gamma and R^2 for pitch/rotation)),
        ``ridge`` (per joint ``rmse_test``, ``table8``, ``r2_test``, ``torque_std_test``; alpha,
        intercept, parameters), ``excitation_notes``, ``warnings``, ``timings`` (s).
    """
    from kinergy.identify import nursing as nu
    from kinergy.identify.metrics import r_squared
    from kinergy.simulate import TwinSettings

    say = progress or (lambda _msg: None)
    if robot.n != 6:
        raise KinergyError(
            f"the nursing study runs Table 6's excitation: 6 joints, {robot.name} has {robot.n}"
        )

    def settings(k: int) -> TwinSettings:
        return TwinSettings(seed=seed + k) if noise else TwinSettings.exact()

    timings: dict[str, float] = {}
    t0 = time.perf_counter()
    datas = []
    friction = []
    for j, joint in enumerate(robot.joints):
        say(f"friction runs of joint {j + 1} ({joint.name}) on the twin")
        run = nu.back_and_forth_motion(robot, j)
        data = _twin_log(robot, f"twin:friction-{joint.name}", run.motion, settings(j))
        datas.append(data)
        tau = nu.joint_torques_from_current(robot, data.current)
        pts = nu.friction_points(
            data.q[:, j], tau[:, j], run.speeds, run.forward, run.backward, joint=j
        )
        fits = {
            "pso": nu.fit_makkar_pso(pts.speeds, pts.friction, rng=seed),
            "lsq": nu.fit_makkar_lsq(pts.speeds, pts.friction),
        }
        truth = nu.joint_side_makkar(robot, j)
        kind = nu.joint_kind(robot, j)
        entry: dict[str, Any] = {
            "joint": j + 1,
            "name": joint.name,
            "kind": kind,
            "levels": int(pts.speeds.size),
            "speed_range": [float(pts.speeds.min()), float(pts.speeds.max())],
            "tilt": run.tilt,
            "error_max": float(np.max(np.abs(pts.error))),
        }
        for key, mf in fits.items():
            pred = nu.makkar(mf.gamma, pts.sample_speeds)
            entry[key] = {
                "gamma": mf.gamma.tolist(),
                "r2": mf.r2,
                "r2_samples": float(r_squared(pts.sample_friction[:, None], pred[:, None])[0]),
                "max_rel_error": None
                if truth is None
                else float(np.max(np.abs(mf.gamma / truth - 1.0))),
                "curve_r2_vs_twin": None
                if truth is None
                else float(
                    r_squared(
                        nu.makkar(truth, pts.speeds)[:, None],
                        nu.makkar(mf.gamma, pts.speeds)[:, None],
                    )[0]
                ),
            }
        entry["twin"] = None if truth is None else truth.tolist()
        entry["doc"] = (
            {"gamma": list(nu.DOC_TABLE4[kind]), "r2": nu.DOC_FRICTION_R2[kind]}
            if kind in nu.DOC_TABLE4
            else None
        )
        friction.append(entry)
    timings["friction"] = time.perf_counter() - t0

    t1 = time.perf_counter()
    say("Table 6 excitation, 10 periods, on the twin")
    motion, _, notes = nu.table6_motion(robot, periods=10)
    datas.append(_twin_log(robot, "twin:excitation-table6", motion, settings(robot.n)))
    timings["excitation"] = time.perf_counter() - t1

    t2 = time.perf_counter()
    say("identifying (nursing method: Makkar friction per motor, ridge on the minimal set)")
    result = nu.identify_nursing(robot, datas, fit="lsq", seed=seed)
    timings["identify"] = time.perf_counter() - t2
    fit = result.fit
    assert isinstance(fit, nu.NursingFit) and fit.ridge is not None and fit.base_parameters
    ridge = fit.ridge
    out = {
        "robot": robot.name,
        "noise": noise,
        "seed": seed,
        "friction": friction,
        "ridge": {
            "joints": robot.joint_names,
            "rmse_test": ridge["rmse_test"],
            "rmse_train": ridge["rmse_train"],
            "r2_test": ridge["r2_test"],
            "torque_std_test": ridge["torque_std_test"],
            "table8": list(nu.DOC_TABLE8),
            "alpha": ridge["alpha"],
            "intercept": ridge["intercept"],
            "parameters": len(fit.base_parameters),
            "split": ridge["split"],
            "period": ridge["logs"][0]["period"],
            "cutoff": ridge["logs"][0].get("cutoff"),
        },
        "friction_motors": fit.friction_motors,
        "excitation_notes": notes,
        "warnings": result.warnings,
        "timings": timings,
    }
    return out


def _gamma(g: list[float] | None) -> list[str]:
    return ["-"] * 6 if g is None else [f"{x:.4g}" if abs(x) > 1e-9 else "0" for x in g]


def study_text(study: dict[str, Any]) -> str:
    """The study as the two tables the command prints."""
    noise = "the twin's default noise" if study["noise"] else "no noise"
    lines = [
        f"{study['robot']} twin, {noise} (seed {study['seed']}): nursing doc sections 4.1-4.2",
        "",
        "Makkar friction, joint side (nursing eq 13, Table 4): gamma1..6 in N m, s/rad, s/rad, N m, "
        "s/rad, N m s/rad",
    ]
    rows = []
    for e in study["friction"]:
        label = f"{e['joint']} {e['name']}"
        for key, name in (("pso", "PSO"), ("lsq", "LSQ")):
            fit = e[key]
            rows.append(
                [
                    label,
                    e["kind"],
                    name,
                    *_gamma(fit["gamma"]),
                    f"{fit['r2']:.4f}",
                    f"{fit['r2_samples']:.4f}",
                    "-",
                ]
            )
            label = ""
        rows.append(["", "", "twin", *_gamma(e["twin"]), "-", "-", "-"])
    for kind in ("pitch", "rotation"):
        doc = next((e["doc"] for e in study["friction"] if e["kind"] == kind and e["doc"]), None)
        if doc is not None:
            rows.append(
                ["doc Table 4", kind, "PSO", *_gamma(doc["gamma"]), "-", "-", f"{doc['r2']:.3f}"]
            )
    lines.append(
        table(
            [
                "joint",
                "kind",
                "fit",
                "g1",
                "g2",
                "g3",
                "g4",
                "g5",
                "g6",
                "R2 levels",
                "R2 samples",
                "R2 doc",
            ],
            rows,
        )
    )
    first = study["friction"][0]
    lines += [
        f"{first['levels']} speeds per joint from {first['speed_range'][0]:.3g} rad/s to each joint's "
        "limit; friction = the odd part of the torque from the currents (eq 20).",
        "R2 levels: the fit against the friction of each speed level (the mean over its run); R2 samples: "
        "against every sample's odd part, the scatter of the doc's Figure 8.",
        "twin: the robot file's motor-side Makkar parameters on the joint side (gamma1, gamma4 x k n; "
        "rates x n; gamma6 x k n^2; k motors per joint at n = gear ratio).",
        *[
            f"joint {e['joint']}'s axis cannot be made vertical (tilt {np.degrees(e['tilt']):.0f} deg): "
            "gravity cancels in the odd part by pairing equal positions (largest even part "
            f"{e['error_max']:.3g} N m)."
            for e in study["friction"]
            if e["tilt"] > 1e-3
        ],
        "",
    ]
    r = study["ridge"]
    rows = [
        [
            name,
            f"{rm:.4f}",
            f"{sd:.4f}",
            f"{r2:.4f}",
            f"{doc:.3f}",
        ]
        for name, rm, sd, r2, doc in zip(
            r["joints"],
            r["rmse_test"],
            r["torque_std_test"],
            r["r2_test"],
            r["table8"],
            strict=True,
        )
    ]
    lines += [
        f"Joint torque RMSE on the last {100 - round(100 * r['split'])} % (nursing eq 26, Table 8): ridge "
        f"regression of the {r['parameters']} minimal parameters",
        table(["joint", "RMSE [N m]", "std [N m]", "R2", "Table 8 [N m]"], rows),
        f"Table 6 excitation, {r['period']:.4g} s period x 10, currents low-pass {r['cutoff']} Hz, averaged "
        f"over the periods (eq 24); ridge alpha {r['alpha']:.3g} by GCV, intercept {r['intercept']:.3g} N m. "
        "std: the regressed torques' spread on the test part.",
    ]
    for note in study["excitation_notes"]:
        lines.append(f"note: {note}")
    for warning in study["warnings"]:
        lines.append(f"warning: {warning}")
    t = study["timings"]
    lines.append(
        f"time: friction runs {t['friction']:.1f} s, excitation {t['excitation']:.1f} s, "
        f"identification {t['identify']:.1f} s"
    )
    return "\n".join(lines)


@click.command("nursing")
@click.argument("robot_name", metavar="[ROBOT]", default="nursing-arm")
@click.option("--json", "as_json", is_flag=True, help="Print JSON instead of tables.")
@click.option(
    "--noise/--exact",
    default=True,
    show_default=True,
    help="The twin's default lag and noise, or exact signals.",
)
@click.option("--seed", type=int, default=0, show_default=True, help="Seed of the noise and swarm.")
def nursing(robot_name: str, as_json: bool, noise: bool, seed: int) -> None:
    """Run the nursing doc's identification (friction runs, PSO Makkar fit, ridge) on the twin.

    ROBOT is a built-in name or a model file (default nursing-arm). Prints the Makkar parameters
    (PSO and least squares) with R^2 next to the doc's Table 4 and 0.927 / 0.931, and the
    per-joint torque RMSE next to Table 8.
    """
    robot = load_robot(robot_name)

    def say(message: str) -> None:
        if not as_json:
            click.echo(f"... {message}", err=True)

    study = nursing_study(robot, noise=noise, seed=seed, progress=say)
    if as_json:
        click.echo(json.dumps(study, indent=2))
    else:
        click.echo(study_text(study))
