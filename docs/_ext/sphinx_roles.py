"""A griffe extension for the API reference: kinergy's docstrings cite code with Sphinx roles
(``:func:`kinergy.rnea```, ``:class:`~kinergy.model.robot.Robot```), which Markdown does not
know; this shows each as the code name it refers to (``~`` keeps the last component, as Sphinx
does). mkdocs.yml loads it for mkdocstrings; it is not part of the package."""

from __future__ import annotations

import re
from typing import Any

import griffe

ROLE = re.compile(r":(?:py:)?(?:class|func|meth|mod|data|attr|exc|obj|const):`(~?)([^`]+)`")


def plain(text: str) -> str:
    """``text`` with every Sphinx role replaced by a code span of the name it refers to."""

    def name(match: re.Match[str]) -> str:
        target = match.group(2).strip()
        return f"`{target.rsplit('.', 1)[-1] if match.group(1) else target.lstrip('.')}`"

    return ROLE.sub(name, text)


class SphinxRoles(griffe.Extension):
    """Rewrites the Sphinx roles of every docstring as code spans."""

    def on_object(self, *, obj: griffe.Object, **kwargs: Any) -> None:
        if obj.docstring is not None:
            obj.docstring.value = plain(obj.docstring.value)
