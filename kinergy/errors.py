"""The one exception type kinergy raises for user errors.

Every error a user can cause (a bad robot file, a malformed log, arrays of the wrong shape) is a
:class:`KinergyError` whose message is one line naming the file, field, line, column or joint at
fault. The command line prints that line and exits non-zero; it never shows a traceback for one.
"""

from __future__ import annotations

__all__ = ["KinergyError"]


class KinergyError(ValueError):
    """A user error: bad input, a bad robot file, data that cannot answer the question asked.

    The message is a single line that names what is wrong and where.
    """

    def prefixed(self, where: str) -> KinergyError:
        """Return a copy of this error with ``where: `` put in front of its message."""
        return type(self)(f"{where}: {self}")
