"""MkDocs hook: the command-line page says what the commands say.

mkdocs-click renders each option's default as click stores it, which for an option with no
default is click's ``UNSET`` sentinel (printed ``Sentinel.UNSET``), and each subcommand's summary
as the first line of its help text, cut wherever the line ends. This hook, on the page's HTML,
leaves a default that is not set empty and gives each summary the first sentence of the
command's help.
"""

from __future__ import annotations

import html
import re
from typing import Any

import click

_UNSET = re.compile(r"<code>Sentinel\.UNSET</code>")
_SUMMARY = re.compile(r'(<li><em><a href="#(kinergy(?:-[\w-]+)?)">[^<]+</a></em>: )([^<]*)(</li>)')


def _anchors(command: click.Command, anchor: str, out: dict[str, str]) -> dict[str, str]:
    """Each command's page anchor (``kinergy-robot-list``) -> the first sentence of its help."""
    text = " ".join((command.help or "").split("\n\n")[0].split())
    match = re.match(r"(.+?\.)(?:\s|$)", text)
    out[anchor] = match.group(1) if match else text
    if isinstance(command, click.Group):  # its commands may be loaded on demand
        ctx = click.Context(command)
        for name in command.list_commands(ctx):
            sub = command.get_command(ctx, name)
            if sub is not None:
                _anchors(sub, f"{anchor}-{name}", out)
    return out


def on_page_content(content: str, page: Any, **kwargs: Any) -> str:
    """The CLI page's HTML with no ``Sentinel.UNSET`` and whole summaries."""
    if page.file.src_uri != "cli.md":
        return content
    from kinergy.cli.app import cli

    summaries = _anchors(cli, "kinergy", {})
    content = _UNSET.sub("", content)

    def whole(match: re.Match[str]) -> str:
        text = summaries.get(match.group(2))
        return (
            match.group(0) if text is None else match.group(1) + html.escape(text) + match.group(4)
        )

    return _SUMMARY.sub(whole, content)
