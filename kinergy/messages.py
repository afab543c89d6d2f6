"""What a computation tells its user besides its result, by weight.

A *note* is routine: a value written into a model, a default used, how a log was read. A
*warning* is what may make a result wrong: a fit the data does not support, a log that passed its
checks only just. (Errors are :class:`kinergy.errors.KinergyError`.) The command line prints both
on stderr (``kinergy: note: ...``, ``kinergy: warning: ...``; ``--quiet`` drops the notes) and
``--json`` carries both lists.

A message is a :class:`Message`: its text, and a :class:`~kinergy.errors.Code` where a caller
must pick it out (``PayloadRun.lacks`` takes the warnings coded ``PAYLOAD_MISSING``), so that no
caller searches the text.

Long work says how far it is through a :class:`Say` hook: a step's name, and where the step has
parts (placements, logs, starts) how many of them are done, so that a terminal shows a fraction
and the time left (the command line's progress bar; nothing on a pipe).
"""

from __future__ import annotations

import inspect
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Protocol, cast

from kinergy.errors import Code

__all__ = ["Message", "Messages", "Say", "as_say", "coded", "silent"]


class Say(Protocol):
    """A progress hook: ``say(message)`` starts a step; ``say(message, done=k, total=n)``
    starts or advances a step of ``n`` parts, ``k`` of them done (``0 <= k <= n``)."""

    def __call__(self, message: str, *, done: int | None = None, total: int | None = None) -> None:
        """Say where the work is."""


def silent(message: str, *, done: int | None = None, total: int | None = None) -> None:
    """A :class:`Say` hook that says nothing."""


def as_say(hook: Say | Callable[[str], None] | None) -> Say:
    """``hook`` as a :class:`Say`: itself when it takes ``done`` and ``total``; a hook that
    takes only the message (``print``) gets the parts done appended to it (``placement
    (3/25)``); None: :func:`silent`."""
    if hook is None:
        return silent
    try:
        takes = {"done", "total"} <= set(inspect.signature(hook).parameters)
    except (TypeError, ValueError):  # a builtin without a signature
        takes = False
    if takes:
        return cast(Say, hook)
    plain = cast(Callable[[str], None], hook)

    def say(message: str, *, done: int | None = None, total: int | None = None) -> None:
        plain(message if total is None else f"{message} ({done}/{total})")

    return say


class Message(str):
    """A note's or warning's text (it is a ``str``), with the code of what it reports.

    Examples
    --------
    >>> w = Message("looks like a payload", Code.PAYLOAD_MISSING)
    >>> w.code, w.prefixed("run.csv")
    (<Code.PAYLOAD_MISSING: 'payload_missing'>, 'run.csv: looks like a payload')
    >>> w.prefixed("run.csv").code
    <Code.PAYLOAD_MISSING: 'payload_missing'>
    """

    code: Code | None

    def __new__(cls, text: str, code: Code | None = None) -> Message:
        out = super().__new__(cls, text)
        out.code = code if code is not None else getattr(text, "code", None)
        return out

    def prefixed(self, where: str) -> Message:
        """``where: text``, with the same code."""
        return Message(f"{where}: {self}", self.code)


def coded(texts: list[str] | tuple[str, ...], code: Code) -> list[str]:
    """The messages of ``texts`` that carry ``code``."""
    return [t for t in texts if getattr(t, "code", None) == code]


@dataclass
class Messages:
    """Notes and warnings gathered while a result is computed (module docstring)."""

    notes: list[str] = field(default_factory=list)
    warnings: list[str] = field(default_factory=list)

    def note(self, text: str) -> None:
        """Something routine the user may want to know."""
        self.notes.append(text)

    def warn(self, text: str, code: Code | None = None) -> None:
        """Something that may make the result wrong (``code``: what kind, for callers that pick
        it out)."""
        self.warnings.append(Message(text, code) if code is not None else text)

    def extend(self, other: Messages) -> None:
        self.notes.extend(other.notes)
        self.warnings.extend(other.warnings)
