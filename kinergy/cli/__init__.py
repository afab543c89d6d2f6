"""The ``kinergy`` command line: one module per command; each parses, calls a workflow, prints."""

from kinergy.cli.app import cli, main, run

__all__ = ["cli", "main", "run"]
