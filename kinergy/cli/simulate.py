"""``kinergy simulate``: the digital twin writes the log a UR controller would record."""

from __future__ import annotations

import click

from kinergy.cli.common import (
    Finite,
    accept_option,
    columns_option,
    load,
    log_output,
    log_reading,
    output_file_option,
    payload_option,
    prose,
    refuse_together,
    seed_option,
    tell,
    writes,
)
from kinergy.errors import KinergyError
from kinergy.twin import MISMATCHES, TwinSettings
from kinergy.workflows.twin import simulate_to_file

__all__ = ["simulate"]


@click.command()
@click.argument("robot_name", metavar="ROBOT")
@click.option(
    "--trajectory",
    required=True,
    metavar="test-a|test-b|FILE",
    help="The UR5e doc's test programs, a motion file (record.py layout with target_q) or a "
    "URScript program (*.script, run as the controller runs it; its set_payload is not "
    "simulated: --payload).",
)
@output_file_option("--out", "Log to write.", required=True)
@click.option(
    "--mismatch",
    type=click.Choice(MISMATCHES),
    default="none",
    show_default=True,
    help="none: ROBOT itself is the truth; realistic: a true robot that differs from ROBOT "
    "(inertias, k_t, electrics, concave load- and temperature-dependent friction) with a real "
    "controller's current steps, voltage noise and supply ripple.",
)
@output_file_option(
    "--truth",
    "Write the twin's true robot file here (with --mismatch realistic).",
    dest="truth_out",
)
@click.option("--exact", is_flag=True, help="No lag and no noise: the model's equations exactly.")
@click.option("--lag", type=Finite(0.0, 1.0), help="Real motion behind the target, s [0.004].")
@click.option(
    "--speed-noise",
    type=Finite(0.0, 10.0),
    help="Measured speed noise std, rad/s [0.01].",
)
@click.option(
    "--current-noise",
    type=Finite(0.0, 100.0),
    help="Measured current noise std, A [0.04].",
)
@click.option(
    "--ambient",
    type=Finite(-50.0, 100.0),
    default=25.0,
    show_default=True,
    help="Air, deg C.",
)
@click.option(
    "--initial-temperature",
    type=Finite(-50.0, 200.0),
    default=None,
    help="The joints' temperature at the start, deg C [the ambient: a cold start].",
)
@seed_option
@payload_option
@columns_option
@accept_option
@writes(files=("out", "truth_out"), inputs=("robot_name", "trajectory"))
def simulate(
    robot_name: str,
    trajectory: str,
    out: str,
    mismatch: str,
    truth_out: str | None,
    exact: bool,
    lag: float | None,
    speed_noise: float | None,
    current_noise: float | None,
    ambient: float,
    initial_temperature: float | None,
    seed: int,
    payload: str | None,
    columns: str | None,
    accept: tuple[str, ...],
) -> None:
    """Run the digital twin: write the log a UR controller would record (record.py layout, 500 Hz).

    ROBOT is a built-in name or a model file: the model the twin's truth is (--mismatch none) or
    differs from (--mismatch realistic).
    """
    exact_means = "--exact means no lag and no noise"
    refuse_together(
        ("exact", "lag", exact_means),
        ("exact", "speed_noise", exact_means),
        ("exact", "current_noise", exact_means),
    )
    if truth_out is not None and mismatch != "realistic":
        raise KinergyError(
            "--truth: only with --mismatch realistic (with none the twin's truth is ROBOT itself)"
        )
    log_output("--out", out)
    r = load(robot_name, payload)
    reading = log_reading(r, columns=columns, accept=accept)
    if exact:
        base = TwinSettings.exact()
    elif mismatch == "realistic":
        base = TwinSettings.realistic(seed)
    else:
        base = TwinSettings()
    settings = TwinSettings(
        lag=base.lag if lag is None else lag,
        speed_noise=base.speed_noise if speed_noise is None else speed_noise,
        position_noise=base.position_noise,
        current_noise=base.current_noise if current_noise is None else current_noise,
        seed=seed,
        current_step=base.current_step,
        voltage_noise=base.voltage_noise,
        ripple=base.ripple,
        ambient=ambient,
        initial_temperature=initial_temperature,
    )
    twin, said = simulate_to_file(
        r, trajectory, out, settings, reading=reading, mismatch=mismatch, truth_out=truth_out
    )
    tell(said.notes, said.warnings)
    t = twin.t
    click.echo(
        prose(
            f"wrote {out}: {len(t)} samples, {t[-1] - t[0]:.3f} s, {r.name}, trajectory "
            f"{trajectory}, mismatch {mismatch}, lag {settings.lag * 1e3:g} ms, speed noise "
            f"{settings.speed_noise:g} rad/s, current noise {settings.current_noise:g} A"
            + (f"; true robot: {truth_out}" if truth_out else "")
        )
    )
