"""``kinergy simulate``: the digital twin writes the log a UR controller would record."""

from __future__ import annotations

import click

from kinergy import api
from kinergy.cli.common import (
    as_usage,
    choice_of,
    load,
    log_output,
    output_file_option,
    payload_option,
    prose,
    reading_options,
    seed_option,
    tell,
    writes,
)
from kinergy.logs.reading import LogReading

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
    type=choice_of(api.Mismatch),
    default=api.Mismatch.NONE.value,
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
@click.option("--lag", type=float, help="Real motion behind the target, s, 0 to 1 [0.004].")
@click.option("--speed-noise", type=float, help="Measured speed noise std, rad/s, 0 to 10 [0.01].")
@click.option("--current-noise", type=float, help="Measured current noise std, A, 0 to 100 [0.04].")
@click.option(
    "--ambient", type=float, default=25.0, show_default=True, help="Air, deg C, -50 to 100."
)
@click.option(
    "--initial-temperature",
    type=float,
    default=None,
    help="The joints' temperature at the start, deg C, -50 to 200 [the ambient: a cold start].",
)
@seed_option
@payload_option
@reading_options("columns", "accept")
@writes(files=("out", "truth_out"), inputs=("robot_name", "trajectory"))
def simulate(
    robot_name: str,
    trajectory: str,
    out: str,
    mismatch: api.Mismatch,
    truth_out: str | None,
    exact: bool,
    lag: float | None,
    speed_noise: float | None,
    current_noise: float | None,
    ambient: float,
    initial_temperature: float | None,
    seed: int,
    payload: str | None,
    reading: LogReading,
) -> None:
    """Run the digital twin: write the log a UR controller would record (record.py layout, 500 Hz).

    ROBOT is a built-in name or a model file: the model the twin's truth is (--mismatch none) or
    differs from (--mismatch realistic).
    """
    with as_usage():
        options = api.SimulateOptions(
            mismatch=mismatch, seed=seed, exact=exact, lag=lag, speed_noise=speed_noise,
            current_noise=current_noise, ambient=ambient, initial_temperature=initial_temperature,
        )  # fmt: skip
    log_output("--out", out)
    r = load(robot_name, payload)
    twin = api.simulate(r, trajectory, options, reading=reading, out=out, truth_out=truth_out)
    tell(twin.notes, twin.warnings)
    t, settings = twin.log.t, twin.settings
    click.echo(
        prose(
            f"wrote {out}: {len(t)} samples, {t[-1] - t[0]:.3f} s, {r.name}, trajectory "
            f"{trajectory}, mismatch {mismatch}, lag {settings.lag * 1e3:g} ms, speed noise "
            f"{settings.speed_noise:g} rad/s, current noise {settings.current_noise:g} A"
            + (f"; true robot: {truth_out}" if truth_out else "")
        )
    )
