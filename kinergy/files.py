"""Output files written whole or not at all, never over an input, and TOML read safely.

Every file kinergy writes goes through :func:`atomic_write` (or :func:`atomic_folder` for a folder
of outputs): the content goes to a temporary file beside the target, is flushed to disk (fsync)
and renamed into place, so a reader never sees half a file and a failure, Ctrl-C or SIGTERM
leaves no temporary behind and the old file untouched. :func:`check_outputs` refuses, before
anything is computed, an output that is one of the command's inputs or another output, and an
existing path that is not a regular file (a device such as ``/dev/null``, a FIFO, a socket, a
folder, a symbolic link), which renaming over would destroy.
"""

from __future__ import annotations

import contextlib
import hashlib
import os
import shutil
import signal
import stat
import sys
import tempfile
import tomllib
from collections.abc import Callable, Iterator, Sequence
from pathlib import Path
from types import FrameType
from typing import IO, Any

from kinergy.errors import KinergyError

__all__ = [
    "MARKER",
    "MAX_TOML_BYTES",
    "Terminated",
    "all_or_none",
    "atomic_folder",
    "atomic_open",
    "atomic_write",
    "check_folder",
    "check_output",
    "check_outputs",
    "check_parent",
    "check_replaceable",
    "output_folder",
    "raise_pending",
    "read_text",
    "read_toml",
    "terminate_on_signals",
]

#: a file kinergy puts into every folder it writes, listing every file it wrote there (SHA-256
#: and path), so it may replace that folder later when nothing else is in it
MARKER = ".kinergy-output"
_MARKER_HEAD = "written by kinergy; it may replace this folder while it holds only these files"
#: a TOML file larger than this is refused before it is read (robot and task files are a few kB)
MAX_TOML_BYTES = 16 * 1024 * 1024

PathLike = str | os.PathLike[str]


class Terminated(BaseException):
    """SIGTERM arrived: raised in the main thread so that every cleanup runs on the way out."""


#: signals that arrived inside :func:`terminate_on_signals`. A handler's exception raised while
#: C code is calling back into Python (numba compiling through llvmlite's ctypes callbacks) is
#: printed and dropped by that callback, so the signal is kept here and raised again before the
#: next output is put in place (:func:`raise_pending`) and at the end of the block.
_PENDING: list[int] = []


def _interruption(signum: int) -> BaseException:
    return KeyboardInterrupt() if signum == signal.SIGINT else Terminated(signum)


def raise_pending() -> None:
    """Raise the interruption of a signal that arrived (and may have been dropped) inside
    :func:`terminate_on_signals`: :class:`Terminated` for SIGTERM, KeyboardInterrupt for SIGINT."""
    if _PENDING:
        raise _interruption(_PENDING[0])


@contextlib.contextmanager
def terminate_on_signals() -> Iterator[None]:
    """Inside the block SIGTERM raises :class:`Terminated` and SIGINT KeyboardInterrupt, so
    temporaries are removed and no half-written output stays behind; a signal whose exception a
    C callback dropped is raised again before the next output is renamed into place and at the
    end of the block (:data:`_PENDING`), and the dropped exception is not printed."""

    def interrupt(signum: int, frame: FrameType | None) -> None:
        _PENDING.append(signum)
        raise _interruption(signum)

    def unraisable(info: Any) -> None:
        if not isinstance(info.exc_value, Terminated | KeyboardInterrupt):
            hook(info)

    # SIGINT only where it interrupts already (a shell's background job starts with it ignored)
    kinds = [signal.SIGTERM]
    if signal.getsignal(signal.SIGINT) is signal.default_int_handler:
        kinds.append(signal.SIGINT)
    try:
        previous = {s: signal.signal(s, interrupt) for s in kinds}
    except ValueError:  # not the main thread: leave signals alone
        yield
        return
    hook, sys.unraisablehook = sys.unraisablehook, unraisable
    try:
        yield
        raise_pending()
    finally:
        sys.unraisablehook = hook
        for s, handler in previous.items():
            signal.signal(s, handler)
        _PENDING.clear()


#: bytes of an existing output's start and end searched for kinergy's mark
MARK_SPAN = 65536


def _marked(path: Path, size: int) -> bool:
    """Whether kinergy wrote the file at ``path`` (``size`` bytes): its name in the first or
    last :data:`MARK_SPAN` bytes (the header comment of a robot file, a URDF, an MJCF model or
    a URScript program; a PNG's ``Software`` text; a Parquet file's footer metadata). A log
    (CSV, as UR's record.py writes it) carries no mark: kinergy never replaces one."""
    try:
        with path.open("rb") as f:
            head = f.read(MARK_SPAN)
            f.seek(max(0, size - MARK_SPAN))
            tail = f.read(MARK_SPAN)
    except OSError:
        return False
    return b"kinergy" in head or b"kinergy" in tail


def check_output(path: PathLike) -> Path:
    """``path`` as an output: refused when it exists and is not a regular file (device, FIFO,
    socket, folder) or is a symbolic link, or when its folder exists as a file.

    Returns the path. Raises KinergyError, one line naming the path.
    """
    target = Path(path)
    try:
        info = os.lstat(target)
    except FileNotFoundError:
        info = None
    except OSError as exc:
        raise KinergyError(f"{target}: cannot write ({exc.strerror or exc})") from None
    if info is not None:
        if stat.S_ISLNK(info.st_mode):
            raise KinergyError(
                f"{target}: is a symbolic link; give the file it points to, or another name"
            )
        if not stat.S_ISREG(info.st_mode):
            kind = "a folder" if stat.S_ISDIR(info.st_mode) else "not a regular file"
            raise KinergyError(f"{target}: is {kind}; kinergy writes only regular files")

    parent = target.parent
    if parent.exists() and not parent.is_dir():
        raise KinergyError(f"{target}: {parent} is not a folder")
    return target


def check_parent(path: PathLike) -> Path:
    """``path`` as a user's output whose folder must exist: kinergy does not create folders for
    it (a mistyped folder would be made silently).

    Returns the path. Raises KinergyError, ``PATH: no such folder FOLDER``.
    """
    target = Path(path)
    parent = target.parent
    if not parent.is_dir():
        raise KinergyError(f"{target}: no such folder {parent}; create it first")
    return target


def check_replaceable(path: PathLike) -> Path:
    """``path`` as a user's output (``--out``, ``out=``): :func:`check_output`, and refused when
    it exists with content kinergy did not write (:func:`_marked`: a log, a program, any file
    of the user's is never replaced).

    Returns the path. Raises KinergyError, one line naming the path.
    """
    target = check_output(path)
    check_parent(target)
    if target.is_file():
        size = target.stat().st_size
        if size > 0 and not _marked(target, size):
            if target.suffix.lower() in (".csv", ".txt", ".log"):
                raise KinergyError(
                    f"{target}: exists: kinergy never replaces a log, not even one it simulated "
                    "(a log carries no mark to tell it from one recorded on a robot); give a new "
                    "name or remove it"
                )
            raise KinergyError(
                f"{target}: exists and kinergy did not write it (a program, a model, a file of "
                "yours): kinergy replaces only its own outputs; give a new name or remove it"
            )
    return target


def _same(a: Path, b: Path) -> bool:
    if a.exists() and b.exists():
        with contextlib.suppress(OSError):
            return os.path.samefile(a, b)
    return a.resolve() == b.resolve()


def check_outputs(
    outputs: Sequence[tuple[str, PathLike | None]], inputs: Sequence[PathLike]
) -> None:
    """Refuse outputs that would destroy an input or each other, before any work is done.

    Parameters
    ----------
    outputs : sequence of (flag, path or None)
        Each output with the flag that named it (``--out``); None: not asked for.
    inputs : sequence of path
        Every file the command reads (logs, robot and task files, programs).

    Raises
    ------
    KinergyError
        ``--out log.csv: is also an input (log.csv); choose another name``, and the like.
    """
    given = [(flag, Path(p)) for flag, p in outputs if p is not None]
    for k, (flag, path) in enumerate(given):
        for source in inputs:
            if _same(path, Path(source)):
                raise KinergyError(
                    f"{flag} {path}: is also an input ({source}); choose another name"
                )
        for other_flag, other in given[:k]:
            if _same(path, other):
                raise KinergyError(f"{flag} {path}: is also the output of {other_flag}")


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


def _fsync_folder(folder: Path) -> None:
    with contextlib.suppress(OSError):  # not every file system lets a folder be opened
        fd = os.open(folder, os.O_RDONLY)
        try:
            os.fsync(fd)
        finally:
            os.close(fd)


@contextlib.contextmanager
def atomic_open(path: PathLike, *, binary: bool = False) -> Iterator[IO[Any]]:
    """A handle to a temporary file beside ``path`` that becomes ``path`` when the ``with``
    block ends without an exception: flushed to disk and renamed into place, so readers never
    see a half-written file and a failure (an exception, Ctrl-C, SIGTERM under
    :func:`terminate_on_signals`) leaves nothing behind. For output written as it is computed
    (a trace of a long log).

    Raises
    ------
    KinergyError
        ``PATH: cannot write (reason)``, or :func:`check_output`'s refusals.
    """
    target = check_output(path)
    with _temporary(target) as (fd, tmp):
        try:
            mode = "wb" if binary else "w"
            kwargs: dict[str, Any] = {} if binary else {"encoding": "utf-8", "newline": "\n"}
            with os.fdopen(fd, mode, **kwargs) as handle:
                yield handle
                handle.flush()
                os.fsync(handle.fileno())
            os.chmod(tmp, 0o644)  # mkstemp makes it private; outputs are for reading
            raise_pending()
            os.replace(tmp, target)
        except OSError as exc:
            raise KinergyError(f"{target}: cannot write ({exc.strerror or exc})") from None
    _fsync_folder(target.parent)


def atomic_write(
    path: PathLike, write: Callable[[IO[Any]], object], *, binary: bool = False
) -> Path:
    """Write a file through ``write(handle)``, whole or not at all (:func:`atomic_open`).

    Raises
    ------
    KinergyError
        ``PATH: cannot write (reason)``, or :func:`check_output`'s refusals.
    """
    with atomic_open(path, binary=binary) as handle:
        write(handle)
    return Path(path)


def _sha256(path: Path) -> str:
    digest = hashlib.sha256()
    with path.open("rb") as f:
        for block in iter(lambda: f.read(1 << 20), b""):
            digest.update(block)
    return digest.hexdigest()


def _files(folder: Path) -> list[Path]:
    """Everything below ``folder`` but the marker and the folders themselves, in order."""
    return sorted(p for p in folder.rglob("*") if not p.is_dir() and p != folder / MARKER)


def _manifest(folder: Path) -> str:
    """The marker's text for ``folder`` as it is: a header, then a line ``SHA-256 path`` per file."""
    lines = [_MARKER_HEAD]
    lines += [f"{_sha256(f)} {f.relative_to(folder).as_posix()}" for f in _files(folder)]
    return "\n".join(lines) + "\n"


def _foreign(folder: Path) -> Path | None:
    """A file in ``folder`` that kinergy did not write there or that changed since, or a folder
    in it holding none of kinergy's files (None: there is none, the folder is kinergy's to
    replace). Without a marker listing its files, every file and folder is foreign."""
    written: dict[str, str] = {}
    marker = folder / MARKER
    if marker.is_file() and not marker.is_symlink():
        text = marker.read_text(encoding="utf-8", errors="replace").splitlines()
        if text[:1] == [_MARKER_HEAD]:
            for line in text[1:]:
                digest, _, rel = line.partition(" ")
                written[rel] = digest
    for f in _files(folder):
        rel = f.relative_to(folder).as_posix()
        if f.is_symlink() or not f.is_file() or written.get(rel) != _sha256(f):
            return f
    for d in sorted(p for p in folder.rglob("*") if p.is_dir()):
        # a folder of the user's, even an empty one (a folder named report.html), or a link to
        # one: kinergy's own folders hold the files it wrote
        rel = d.relative_to(folder).as_posix() + "/"
        if d.is_symlink() or not any(name.startswith(rel) for name in written):
            return d
    return None


def check_folder(path: PathLike) -> Path:
    """``path`` as a folder of outputs (:func:`atomic_folder`): refused, before any work, when it
    is a file or a link, or a folder holding a file kinergy did not write there (or changed since:
    the marker lists what it wrote, by SHA-256) or a folder of the user's (an empty one too); an
    empty folder is taken.

    Returns the path. Raises KinergyError, one line naming it.
    """
    target = Path(path)
    if target.is_symlink() or (target.exists() and not target.is_dir()):
        raise KinergyError(f"{target}: is not a folder; give an empty or new folder")
    if target.is_dir():
        other = _foreign(target)
        if other is not None:
            kind = " (a folder)" if other.is_dir() else ""
            raise KinergyError(
                f"{target}: holds {other.relative_to(target)}{kind}, which kinergy did not write "
                "there (or which changed since): replacing the folder would delete it; give an "
                "empty or new folder"
            )
    if target.parent.exists() and not target.parent.is_dir():
        raise KinergyError(f"{target}: {target.parent} is not a folder")
    check_parent(target)
    return target


@contextlib.contextmanager
def atomic_folder(path: PathLike) -> Iterator[Path]:
    """Build a folder of outputs beside ``path`` and rename it into place at the end.

    Yields the temporary folder to write into. On success it replaces ``path`` (which must be
    missing, empty, or a folder kinergy wrote before); on any failure it is removed and ``path``
    is untouched.

    Raises
    ------
    KinergyError
        ``path`` is a file, a link, or a folder with other content (one line naming it).
    """
    target = check_folder(path)
    try:
        target.parent.mkdir(parents=True, exist_ok=True)
        building = Path(tempfile.mkdtemp(prefix=f".{target.name}.", dir=target.parent))
    except OSError as exc:
        raise KinergyError(f"{target}: cannot write ({exc.strerror or exc})") from None
    try:
        yield building
        (building / MARKER).write_text(_manifest(building), encoding="utf-8")
        os.chmod(building, 0o755)
        raise_pending()
        check_folder(target)  # nothing appeared in it while the outputs were computed
        old = None
        if target.exists():
            old = target.with_name(f".{target.name}.old-{os.getpid()}")
            os.replace(target, old)
        os.replace(building, target)
        if old is not None:
            shutil.rmtree(old, ignore_errors=True)
    except BaseException:
        shutil.rmtree(building, ignore_errors=True)
        raise


@contextlib.contextmanager
def output_folder(path: PathLike | None, *, prefix: str) -> Iterator[tuple[Path, Path]]:
    """:func:`atomic_folder` for ``path``, or with ``path`` None for a new folder
    ``PREFIX-XXXXXXXX`` in the system's temporary folder (so nothing is written to the current
    folder unless asked; a failure removes it again).

    Yields ``(building, target)``: the folder to write into and where it ends up.
    """
    fresh = path is None
    target = Path(tempfile.mkdtemp(prefix=f"{prefix}-")) if path is None else Path(path)
    try:
        with atomic_folder(target) as building:
            yield building, target
    except BaseException:
        if fresh:
            shutil.rmtree(target, ignore_errors=True)
        raise


@contextlib.contextmanager
def all_or_none() -> Iterator[list[Path]]:
    """Outputs written together: append each path written to the list this yields; should
    anything fail (or the run be stopped) before the block ends, every path on it is removed, so
    no partial set of outputs is left behind."""
    written: list[Path] = []
    try:
        yield written
    except BaseException:
        for path in written:
            path.unlink(missing_ok=True)
        raise


def read_text(path: PathLike, what: str, *, max_bytes: int | None = None) -> str:
    """The text of a UTF-8 file; ``what`` names the kind of file in messages ("robot file").

    Parameters
    ----------
    path : str or os.PathLike
    what : str
        The kind of file, as messages name it.
    max_bytes : int, optional
        A larger file is refused before it is read.

    Raises
    ------
    KinergyError
        ``PATH: cannot read WHAT (reason)``, ``PATH: not a text (UTF-8) file``, or
        ``PATH: S MB is too large for a WHAT (at most M MiB)``.
    """
    path = Path(path)
    try:
        size = path.stat().st_size
        if max_bytes is not None and size > max_bytes:
            raise KinergyError(
                f"{path}: {size / 1e6:.1f} MB is too large for a {what} "
                f"(at most {max_bytes // (1024 * 1024)} MiB)"
            )
        return path.read_text(encoding="utf-8-sig")  # a byte-order mark is not text
    except OSError as exc:
        raise KinergyError(f"{path}: cannot read {what} ({exc.strerror})") from None
    except UnicodeDecodeError:
        raise KinergyError(f"{path}: not a text (UTF-8) file{_encoding_hint(path)}") from None


def _encoding_hint(path: Path) -> str:
    """What a file that is not UTF-8 most likely is, for the message."""
    try:
        with path.open("rb") as fh:
            head = fh.read(4096)
    except OSError:
        return ""
    if head.startswith((b"\xff\xfe", b"\xfe\xff")) or (head[1::2].count(0) > len(head) // 4):
        return ": it is UTF-16; save it as UTF-8"
    return ""


def _huge_integer(data: Any, where: str = "") -> str | None:
    """The key path of the first integer in parsed TOML ``data`` that no float holds."""
    if isinstance(data, dict):
        for key, value in data.items():
            found = _huge_integer(value, f"{where}.{key}" if where else str(key))
            if found:
                return found
    elif isinstance(data, list):
        for k, value in enumerate(data):
            found = _huge_integer(value, f"{where}[{k}]")
            if found:
                return found
    elif isinstance(data, int) and not isinstance(data, bool) and abs(data) > 1e300:
        return where
    return None


def read_toml(path: PathLike, what: str) -> dict[str, Any]:
    """Parse a TOML file; ``what`` names the kind of file in messages ("robot file").

    Raises
    ------
    KinergyError
        The messages of :func:`read_text` (with at most :data:`MAX_TOML_BYTES`),
        ``PATH: not valid TOML: ... (line L column C)``, or nesting too deep to be a robot or
        task file.
    """
    text = read_text(path, what, max_bytes=MAX_TOML_BYTES)
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise KinergyError(f"{path}: not valid TOML: {exc}") from None
    except RecursionError:
        raise KinergyError(f"{path}: not a {what}: its tables or arrays nest too deeply") from None
    huge = _huge_integer(data)
    if huge is not None:
        raise KinergyError(f"{path}: {huge}: an integer too large for any number kinergy reads")
    return data
