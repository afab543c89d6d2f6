"""Writing output files whole or not at all."""

from __future__ import annotations

import contextlib
import os
import tempfile
import tomllib
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import IO, Any

from kinergy.errors import KinergyError

__all__ = ["atomic_write", "read_toml"]


@contextlib.contextmanager
def _temporary(target: Path) -> Iterator[tuple[int, str]]:
    try:
        target.parent.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(prefix=f".{target.name}.", suffix=".tmp", dir=target.parent)
    except OSError as exc:
        raise KinergyError(f"{target}: cannot write ({exc.strerror or exc})") from None
    try:
        yield fd, tmp
    except BaseException:
        with contextlib.suppress(OSError):
            os.unlink(tmp)
        raise


def atomic_write(
    path: str | os.PathLike[str], write: Callable[[IO[Any]], object], *, binary: bool = False
) -> Path:
    """Write a file through ``write(handle)`` into a temporary file beside it, then rename it
    into place: readers never see a half-written file, and a failure leaves nothing behind.

    Raises
    ------
    KinergyError
        ``PATH: cannot write (reason)`` when the folder or file cannot be written.
    """
    target = Path(path)
    with _temporary(target) as (fd, tmp):
        try:
            mode = "wb" if binary else "w"
            kwargs: dict[str, Any] = {} if binary else {"encoding": "utf-8", "newline": "\n"}
            with os.fdopen(fd, mode, **kwargs) as handle:
                write(handle)
            os.chmod(tmp, 0o644)  # mkstemp makes it private; outputs are for reading
            os.replace(tmp, target)
        except OSError as exc:
            raise KinergyError(f"{target}: cannot write ({exc.strerror or exc})") from None
    return target


def read_toml(path: str | os.PathLike[str], what: str) -> dict[str, Any]:
    """Parse a TOML file; ``what`` names the kind of file in messages ("robot file").

    Raises
    ------
    KinergyError
        ``PATH: cannot read WHAT (reason)``, ``PATH: not a text (UTF-8) file`` or
        ``PATH: not valid TOML: ... (line L column C)``.
    """
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8")
    except OSError as exc:
        raise KinergyError(f"{path}: cannot read {what} ({exc.strerror})") from None
    except UnicodeDecodeError:
        raise KinergyError(f"{path}: not a text (UTF-8) file") from None
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise KinergyError(f"{path}: not valid TOML: {exc}") from None
