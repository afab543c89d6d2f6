"""``kinergy nursing``: the coupled-drive nursing arm's identification, run on the digital twin.

The command parses, runs :func:`kinergy.workflows.nursing.nursing_study` (the nursing doc's
sections 4.1-4.2 end to end) and prints its two tables: the Makkar friction fits (nursing eq 13)
next to the twin's curve and the doc's Table 4, and the joint-torque RMSE (eq 26) next to Table 8.
"""

from __future__ import annotations

import click
import numpy as np

from kinergy import api
from kinergy.cli.common import (
    as_usage,
    json_result,
    output_file_option,
    progress,
    seed_option,
    table,
    tell,
    writes,
)

__all__ = ["nursing", "study_text"]

_FRICTION_HEADERS = (
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
)


def _gamma(g: tuple[float, ...] | None) -> list[str]:
    return ["-"] * 6 if g is None else [f"{x:.4g}" if abs(x) > 1e-9 else "0" for x in g]


def _friction_rows(study: api.NursingStudy) -> list[list[str]]:
    """Per joint its PSO and LSQ fits and the twin's curve; then the doc's Table 4 curves."""
    rows = []
    for e in study.friction:
        label = f"{e.joint} {e.name}"
        for fit, name in ((e.pso, "PSO"), (e.lsq, "LSQ")):
            r2 = [f"{fit.r2:.4f}", f"{fit.r2_samples:.4f}", "-"]
            rows.append([label, e.kind, name, *_gamma(fit.gamma), *r2])
            label = ""
        rows.append(["", "", "twin", *_gamma(e.twin), "-", "-", "-"])
    for kind in ("pitch", "rotation"):
        doc = next((e.doc for e in study.friction if e.kind == kind and e.doc), None)
        if doc is not None:
            rows.append(["doc Table 4", kind, "PSO", *_gamma(doc.gamma), "-", "-", f"{doc.r2:.3f}"])
    return rows


def _friction_text(study: api.NursingStudy) -> list[str]:
    """The friction table with its caption and notes."""
    first = study.friction[0]
    return [
        "Makkar friction, joint side (nursing eq 13, Table 4): gamma1..6 in N m, s/rad, s/rad, N m, "
        "s/rad, N m s/rad",
        table(_FRICTION_HEADERS, _friction_rows(study)),
        f"{first.levels} speeds per joint from {first.speed_range[0]:.3g} rad/s to each joint's "
        "limit; friction = the odd part of the torque from the currents (eq 20).",
        "R2 levels: the fit against the friction of each speed level (the mean over its run); R2 samples: "
        "against every sample's odd part, the scatter of the doc's Figure 8.",
        "twin: the robot file's motor-side Makkar parameters on the joint side (gamma1, gamma4 x k n; "
        "rates x n; gamma6 x k n^2; k motors per joint at n = gear ratio).",
        *[
            f"joint {e.joint}'s axis cannot be made vertical (tilt {np.degrees(e.tilt):.0f} deg): "
            "gravity cancels in the odd part by pairing equal positions (largest even part "
            f"{e.error_max:.3g} N m)."
            for e in study.friction
            if e.tilt > 1e-3
        ],
    ]


def _ridge_text(study: api.NursingStudy) -> list[str]:
    """The RMSE table against Table 8 with its caption and note."""
    r = study.ridge
    rows = [
        [name, f"{rm:.4f}", f"{sd:.4f}", f"{r2:.4f}", f"{doc:.3f}"]
        for name, rm, sd, r2, doc in zip(
            r.joints, r.rmse_test, r.torque_std_test, r.r2_test, r.table8, strict=True
        )
    ]
    return [
        f"Joint torque RMSE on the last {100 - round(100 * r.split)} % (nursing eq 26, Table 8): ridge "
        f"regression of the {r.parameters} minimal parameters",
        table(["joint", "RMSE [N m]", "std [N m]", "R2", "Table 8 [N m]"], rows),
        f"Table 6 excitation, {r.period:.4g} s period x 10, currents low-pass {r.cutoff} Hz, averaged "
        f"over the periods (eq 24); ridge alpha {r.alpha:.3g} by GCV, intercept {r.intercept:.3g} N m. "
        "std: the regressed torques' spread on the test part.",
    ]


def study_text(study: api.NursingStudy) -> str:
    """The study as the two tables the command prints."""
    noise = "the twin's default noise" if study.noise else "no noise"
    t = study.timings
    lines = [
        f"{study.robot} twin, {noise} (seed {study.seed}): nursing doc sections 4.1-4.2",
        "",
        *_friction_text(study),
        "",
        *_ridge_text(study),
        f"time: friction runs {t.friction:.1f} s, excitation {t.excitation:.1f} s, "
        f"identification {t.identify:.1f} s",
    ]
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
@seed_option
@output_file_option(
    "--out", "Also write the study (the --json output) to this file.", metavar="STUDY.json"
)
@writes(files=("out",), inputs=("robot_name",))
def nursing(robot_name: str, as_json: bool, noise: bool, seed: int, out: str | None) -> None:
    """Run the nursing doc's identification (friction runs, PSO Makkar fit, ridge) on the twin.

    ROBOT is a built-in name or a model file (default nursing-arm). Prints the Makkar parameters
    (PSO and least squares) with R^2 next to the doc's Table 4 and 0.927 / 0.931, and the
    per-joint torque RMSE next to Table 8.
    """
    with as_usage():
        options = api.NursingStudyOptions(noise=noise, seed=seed)
    with progress() as say:
        study = api.nursing_study(robot_name, options, out=out, progress=say)
    tell(study.excitation_notes, study.warnings)
    click.echo(json_result(study) if as_json else study_text(study))
    if out is not None and not as_json:
        click.echo(f"wrote {out}")
