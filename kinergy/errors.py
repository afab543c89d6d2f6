"""The one exception type kinergy raises for user errors, and the codes that say what kind.

Every error a user can cause (a bad robot file, a malformed log, arrays of the wrong shape) is a
:class:`KinergyError` whose message is one line naming the file, field, line, column or joint at
fault. The command line prints that line and exits non-zero; it never shows a traceback for one.
A caller that must tell one kind of error from another reads its :attr:`KinergyError.code`
(a :class:`Code`), never its text.
"""

from __future__ import annotations

import enum

__all__ = ["Code", "KinergyError"]


class Code(enum.StrEnum):
    """What kind of problem an error (or a warning, :mod:`kinergy.messages`) reports."""

    #: a value that breaks a rule of its own (the default)
    INVALID = "invalid"
    #: not a finite number, or a number out of its range (:func:`kinergy.checks.number`)
    NUMBER = "number"
    #: numbers of the wrong count or shape (:func:`kinergy.checks.vector`)
    SHAPE = "shape"
    #: a field, key or attribute that is not one of those allowed (:func:`kinergy.checks.known_keys`)
    UNKNOWN_KEY = "unknown_key"
    #: a name that is not one of the choices (:func:`kinergy.checks.choice`)
    UNKNOWN_CHOICE = "unknown_choice"
    #: a required field, attribute or signal is absent
    MISSING = "missing"
    #: a file that cannot be read, or is not of its format
    FILE = "file"
    #: two descriptions of one thing in a file disagree (a URDF edited after kinergy wrote it)
    DISAGREES = "disagrees"
    #: a valid input kinergy cannot handle (a prismatic joint; an option a method does not take)
    UNSUPPORTED = "unsupported"
    #: a warning: the logs fit the robot carrying a payload that the model lacks
    PAYLOAD_MISSING = "payload_missing"


class KinergyError(ValueError):
    """A user error: bad input, a bad robot file, data that cannot answer the question asked.

    The message is a single line that names what is wrong and where.

    Parameters
    ----------
    message : str
        The one line.
    code : Code
        What kind of problem it is (:data:`Code.INVALID` unless said).
    """

    def __init__(self, message: str = "", code: Code = Code.INVALID) -> None:
        super().__init__(message)
        self.code = code

    def __reduce__(self) -> tuple[type[KinergyError], tuple[str, Code]]:
        # pickled whole (a Dask worker's error reaches the client with its code)
        return type(self), (str(self), self.code)

    def prefixed(self, where: str) -> KinergyError:
        """Return a copy of this error with ``where: `` put in front of its message."""
        return type(self)(f"{where}: {self}", self.code)
