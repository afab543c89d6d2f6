"""``kinergy convert``: a log as a ROS 2 bag, a bag (or any log) as a record.py-layout CSV."""

from __future__ import annotations

from pathlib import Path

import click

from kinergy import api
from kinergy.cli.common import log_output, note, reading_options, tell
from kinergy.errors import KinergyError
from kinergy.files import check_output, check_parent

__all__ = ["convert"]


@click.command()
@click.argument("log", metavar="LOG")
@click.option(
    "--to",
    "to",
    type=click.Choice(["bag", "csv"]),
    required=True,
    help="bag: a rosbag2 folder (MCAP storage) as UR's ROS 2 driver records one; csv: UR's "
    "record.py layout.",
)
@click.argument("out", metavar="OUT")
@click.option(
    "--robot",
    "robot_name",
    default="ur5e",
    show_default=True,
    metavar="ROBOT",
    help="The robot the log is of (built-in or file): its joint names and count (every UR arm "
    "gives UR's driver's names, shoulder_pan_joint ... wrist_3_joint).",
)
@reading_options("columns", "topic", "effort", "repair")
def convert(log: str, to: str, out: str, robot_name: str, reading: api.LogReading) -> None:
    """Convert LOG to a ROS 2 bag or a CSV log at OUT (never replaced: a new name).

    --to bag: one sensor_msgs/JointState per sample on /joint_states, its header stamp the
    log's time, position actual_q, velocity actual_qd and effort the log's motor currents
    (actual_current; --effort torque: its measured joint torques), the robot mode on UR's
    topic; the log's other signals are left out (a note names them). --to csv: every signal
    of LOG (a bag's or any log's) in UR's record.py layout, each value written so that it
    reads back as the same number. A log converted to a bag and back is the same log.
    """
    target = Path(out)
    if target.exists() or target.is_symlink():
        raise KinergyError(f"OUT {out}: exists; kinergy never replaces it: give a new name")
    check_parent(check_output(target))
    kind = api.LogKind(to)
    if kind is api.LogKind.CSV:
        log_output("OUT", out)
    elif target.suffix.lower() in (".mcap", ".db3", ".csv", ".txt"):
        raise KinergyError(
            f"OUT {out}: a bag is a folder (its {target.name}.mcap inside): give a name "
            f"without {target.suffix}"
        )
    result = api.convert(log, target, kind, robot_name, reading=reading)
    tell(result.notes, [])
    if result.left_out:
        note(
            f"{log}: not in the bag (a JointState has no field for them): "
            f"{', '.join(result.left_out)}"
        )
    click.echo(
        f"{result.path}: {result.rows} samples of {', '.join(result.signals)} ({kind.value})"
    )
