"""The ``kinergy`` command group and its entry point.

Commands are loaded when invoked (:class:`LazyGroup`), so ``kinergy --help`` and a command that
needs little do not import the whole scientific stack.

Every user error (bad file, unknown robot, malformed input) ends as one line on stderr,
``kinergy: error: ...``, and exit status 1; usage errors (a bad flag value, a missing argument)
are one line too and exit with 2 (click's convention). No traceback is shown for either, and
control characters in a message (a NUL byte from a file) are shown escaped, never sent to the
terminal.
"""

from __future__ import annotations

import importlib
import re
import sys
from collections.abc import Sequence

import click

from kinergy.errors import KinergyError
from kinergy.files import Terminated, terminate_on_signals

__all__ = ["COMMANDS", "NOTES", "QUIET", "LazyGroup", "cli", "main", "one_line", "run"]

#: key in click's ``ctx.meta``: the global ``--quiet`` was given (no progress on stderr)
QUIET = "kinergy.quiet"
#: key in the context object :func:`main` passes: the notes and warnings held back until the
#: command succeeds, as (level, text) with level "note" or "warning"
NOTES = "kinergy.notes"

#: command name -> "module:attribute" of its click command, in the order ``--help`` lists them
COMMANDS = {
    "robot": "kinergy.cli.robot:robot",
    "simulate": "kinergy.cli.simulate:simulate",
    "identify": "kinergy.cli.identify:identify",
    "validate": "kinergy.cli.validate:validate",
    "energy": "kinergy.cli.energy:energy",
    "optimize": "kinergy.cli.optimize:optimize",
    "place": "kinergy.cli.place:place",
    "excite": "kinergy.cli.excite:excite",
    "nursing": "kinergy.cli.nursing:nursing",
    "report": "kinergy.cli.report:report",
    "demo": "kinergy.cli.demo:demo",
    "record": "kinergy.cli.record:record",
    "monitor": "kinergy.cli.monitor:monitor",
    "fleet": "kinergy.cli.fleet:fleet",
    "convert": "kinergy.cli.convert:convert",
}


class LazyGroup(click.Group):
    """A click group whose sub-commands are imported on first use (see :data:`COMMANDS`)."""

    def list_commands(self, ctx: click.Context) -> list[str]:
        return list(COMMANDS)

    def get_command(self, ctx: click.Context, cmd_name: str) -> click.Command | None:
        target = COMMANDS.get(cmd_name)
        if target is None:
            return None
        module, _, attr = target.partition(":")
        command = getattr(importlib.import_module(module), attr)
        assert isinstance(command, click.Command)
        return command


@click.group(cls=LazyGroup, context_settings={"help_option_names": ["-h", "--help"]})
@click.version_option(package_name="kinergy")
@click.option(
    "--quiet",
    "-q",
    is_flag=True,
    help="No progress display and no notes on stderr (warnings stay).",
)
@click.pass_context
def cli(ctx: click.Context, quiet: bool) -> None:
    """Electro-mechanical models of robot arms from controller logs.

    Long steps show their progress on stderr when it is a terminal. Besides its result (on
    stdout), a command says on stderr what is routine ("note:") and what may make the result
    wrong ("warning:"); --quiet drops the progress and the notes.
    """
    ctx.meta[QUIET] = quiet
    if isinstance(ctx.obj, dict):
        ctx.obj[QUIET] = quiet


_CONTROL = re.compile(r"[\x00-\x08\x0b-\x1f\x7f]")


def one_line(message: str) -> str:
    """``message`` on one line: line breaks as spaces, other control characters escaped."""
    flat = " ".join(message.splitlines())
    return _CONTROL.sub(lambda m: repr(m.group())[1:-1], flat)


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point: run the CLI, turning user errors into one line and a non-zero exit."""
    notes: list[tuple[str, str]] = []
    obj: dict[str, object] = {NOTES: notes}
    try:
        with terminate_on_signals():
            cli.main(
                args=list(argv) if argv is not None else None,
                prog_name="kinergy",
                standalone_mode=False,
                obj=obj,
            )
    except KinergyError as exc:
        click.echo(f"kinergy: error: {one_line(str(exc))}", err=True)
        return 1
    except (click.exceptions.Abort, KeyboardInterrupt):
        click.echo("kinergy: interrupted; no output was left half-written", err=True)
        return 130
    except Terminated:
        click.echo("kinergy: terminated; no output was left half-written", err=True)
        return 143
    except click.UsageError as exc:
        click.echo(f"kinergy: error: {one_line(exc.format_message())}", err=True)
        return exc.exit_code
    except click.ClickException as exc:
        click.echo(f"kinergy: error: {one_line(exc.format_message())}", err=True)
        return exc.exit_code
    except click.exceptions.Exit as exc:
        return exc.exit_code
    except BrokenPipeError:
        return 0
    for level, message in notes:
        if level == "note" and obj.get(QUIET):
            continue
        click.echo(f"kinergy: {level}: {one_line(message)}", err=True)
    return 0


def run() -> None:
    """Console-script entry point."""
    sys.exit(main())


if __name__ == "__main__":
    run()
