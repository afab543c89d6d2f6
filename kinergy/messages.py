"""What a computation tells its user besides its result, by weight.

A *note* is routine: a value written into a model, a default used, how a log was read. A
*warning* is what may make a result wrong: a fit the data does not support, a log that passed its
checks only just. (Errors are :class:`kinergy.errors.KinergyError`.) The command line prints both
on stderr (``kinergy: note: ...``, ``kinergy: warning: ...``; ``--quiet`` drops the notes) and
``--json`` carries both lists.
"""

from __future__ import annotations

from dataclasses import dataclass, field

__all__ = ["Messages"]


@dataclass
class Messages:
    """Notes and warnings gathered while a result is computed (module docstring)."""

    notes: list[str] = field(default_factory=list)
    warnings: list[str] = field(default_factory=list)

    def note(self, text: str) -> None:
        """Something routine the user may want to know."""
        self.notes.append(text)

    def warn(self, text: str) -> None:
        """Something that may make the result wrong."""
        self.warnings.append(text)

    def extend(self, other: Messages) -> None:
        self.notes.extend(other.notes)
        self.warnings.extend(other.warnings)
