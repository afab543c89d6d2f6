"""A controller's RTDE data stream that survives dropped connections.

:class:`Stream` connects, subscribes and then reads every data package on a thread of its own
into an unbounded queue, so the consumer (a file writer, the monitor) never makes the controller
wait and no package is overwritten by a newer one. When the connection drops (closed, or silent
for ``stall`` seconds) the thread reconnects with growing pauses (:data:`BACKOFF`) and puts a
:class:`Gap` in the queue before the first package of the new connection: the consumer starts a
new segment there. :func:`stop_on_signals` turns SIGINT and SIGTERM into a request to stop, so a
recording ends with its file flushed and closed.
"""

from __future__ import annotations

import contextlib
import queue
import signal
import threading
import time
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass
from types import FrameType

from kinergy.checks import number
from kinergy.errors import KinergyError
from kinergy.live.rtde import Connection, Recipe

__all__ = [
    "BACKOFF",
    "MAX_FREQUENCY",
    "Gap",
    "RecordOptions",
    "Stream",
    "StreamOptions",
    "stop_on_signals",
]

#: Hz: the fastest a controller sends (a UR e-Series: 500)
MAX_FREQUENCY = 500.0


@dataclass(frozen=True)
class StreamOptions:
    """How long and how fast to follow a controller (``kinergy monitor``), checked on
    construction: one line naming the option.

    Attributes
    ----------
    frequency : float
        Packages per second, Hz, > 0 and <= :data:`MAX_FREQUENCY`.
    duration : float or None
        Stop after this many seconds of controller time (> 0); None: at Ctrl-C or SIGTERM.
    """

    frequency: float = MAX_FREQUENCY
    duration: float | None = None

    def __post_init__(self) -> None:
        frequency = number(self.frequency, "--frequency", gt=0.0, le=MAX_FREQUENCY)
        object.__setattr__(self, "frequency", frequency)
        if self.duration is not None:
            object.__setattr__(self, "duration", number(self.duration, "--duration", gt=0.0))


@dataclass(frozen=True)
class RecordOptions(StreamOptions):
    """:class:`StreamOptions` of ``kinergy record``, and when to start a new file.

    Attributes
    ----------
    rotate_minutes : float or None
        A new file every this many minutes (> 0); None: one file.
    rotate_megabytes : float or None
        A new file every this many MB (> 0); None: one file.
    """

    rotate_minutes: float | None = None
    rotate_megabytes: float | None = None

    def __post_init__(self) -> None:
        super().__post_init__()
        for name, what in (("rotate_minutes", "--rotate"), ("rotate_megabytes", "--rotate-size")):
            value = getattr(self, name)
            if value is not None:
                object.__setattr__(self, name, number(value, what, gt=0.0))


#: seconds to wait before each reconnection attempt (the last repeats)
BACKOFF = (0.1, 0.25, 0.5, 1.0, 2.0, 5.0)

Values = tuple[float | int, ...]


@dataclass(frozen=True)
class Gap:
    """The connection dropped and came back: the next package starts a new segment.

    Attributes
    ----------
    reason : str
        Why it dropped.
    seconds : float
        Wall-clock time from the drop to the new connection, s.
    """

    reason: str
    seconds: float


class Stream:
    """Data packages of ``names`` at ``frequency`` Hz from the controller at ``host:port``.

    The first connection is made in the constructor, so a bad host or a refused connection is
    a :class:`KinergyError` there; later drops are retried until :meth:`close`.

    Parameters
    ----------
    host : str
    port : int
    names : sequence of str
        RTDE output variables.
    frequency : float
        Hz.
    optional : sequence of str
        Variables left out (with a status message) when the controller does not know them.
    stall : float
        Seconds without a package after which the connection counts as dropped.
    status : callable, optional
        Receives one-line messages (connected, dropped, reconnecting, controller text).
    """

    def __init__(
        self,
        host: str,
        port: int,
        names: Sequence[str],
        frequency: float,
        *,
        optional: Sequence[str] = (),
        stall: float = 2.0,
        status: Callable[[str], None] | None = None,
    ) -> None:
        self.host, self.port = host, port
        self.frequency = float(frequency)
        self.stall = stall
        self.status = status or (lambda message: None)
        self.packages: queue.Queue[Values | Gap | None] = queue.Queue()
        self.drops = 0
        self._stopping = threading.Event()
        self._wanted = list(names)
        self._optional = list(optional)
        self._lock = threading.Lock()
        self.connection, self.recipe = self._connect()
        self.version = self._version
        left_out = [n for n in names if n not in self.recipe.names]
        if left_out:
            self.status(f"the controller does not log {', '.join(left_out)}: left out")
        self._thread = threading.Thread(target=self._run, name="rtde-stream", daemon=True)
        self._thread.start()

    def _connect(self) -> tuple[Connection, Recipe]:
        conn = Connection(self.host, self.port, timeout=max(self.stall, 1.0), on_text=self.status)
        try:
            self._version = conn.negotiate()
            recipe = conn.subscribe(self._wanted, self.frequency, optional=self._optional)
        except (OSError, ConnectionError) as exc:
            conn.close()
            raise KinergyError(f"{conn.address}: the handshake failed: {exc}") from None
        except BaseException:
            conn.close()
            raise
        conn.sock.settimeout(self.stall)
        return conn, recipe

    def _read(self, conn: Connection) -> str:
        """Put packages into the queue until the connection ends; return why it ended."""
        layout = self.recipe.layout
        try:
            while True:
                self.packages.put(conn.next_data(self.recipe, layout))
        except TimeoutError:
            return f"no data for {self.stall:g} s"
        except (OSError, ConnectionError) as exc:
            return str(exc) or type(exc).__name__
        finally:
            conn.close()

    def _reconnect(self, reason: str) -> Connection | None:
        """Try again with growing pauses until connected (or asked to stop: None)."""
        attempt = 0
        while True:
            delay = BACKOFF[min(attempt, len(BACKOFF) - 1)]
            self.status(f"connection lost ({reason}); reconnecting in {delay:g} s")
            if self._stopping.wait(delay):
                return None
            attempt += 1
            try:
                conn, recipe = self._connect()
            except KinergyError as exc:
                reason = str(exc)
                continue
            if recipe.names != self.recipe.names or recipe.types != self.recipe.types:
                conn.close()
                reason = "the controller changed the variables' types"
                continue
            self.recipe = recipe
            return conn

    def _run(self) -> None:
        conn: Connection | None = self.connection
        while conn is not None:
            reason = self._read(conn)
            if self._stopping.is_set():
                break
            self.drops += 1
            dropped = time.monotonic()
            conn = self._reconnect(reason)
            with self._lock:
                if conn is not None and self._stopping.is_set():
                    conn.close()
                    conn = None
                self.connection = conn or self.connection
            if conn is not None:
                self.status(f"reconnected after {time.monotonic() - dropped:.2f} s")
                self.packages.put(Gap(reason, time.monotonic() - dropped))
        self.packages.put(None)

    def get(self, timeout: float = 0.2) -> Values | Gap | None:
        """The next item: a package's values, a :class:`Gap`, or None (nothing for ``timeout``
        s, or the stream has ended: see :attr:`ended`)."""
        try:
            return self.packages.get(timeout=timeout)
        except queue.Empty:
            return None

    @property
    def ended(self) -> bool:
        """True once the reading thread has finished (after :meth:`close`)."""
        return not self._thread.is_alive()

    def close(self) -> None:
        """Stop reading: pause the controller, close the connection, end the thread. Packages
        already received stay in the queue (read them with :meth:`get` until it returns None
        and :attr:`ended` is True)."""
        self._stopping.set()
        with self._lock:
            self.connection.pause()
            self.connection.close()
        self._thread.join(timeout=10.0)


@contextlib.contextmanager
def stop_on_signals(stop: threading.Event) -> Iterator[dict[str, str]]:
    """Inside the block SIGINT and SIGTERM set ``stop`` instead of ending the program.

    Yields a dict whose ``"signal"`` entry names the signal that arrived (absent if none). The
    previous handlers are restored when the block ends. Only the main thread may install
    handlers; elsewhere the block changes nothing.
    """
    seen: dict[str, str] = {}

    def handler(signum: int, frame: FrameType | None) -> None:
        seen["signal"] = signal.Signals(signum).name
        stop.set()

    if threading.current_thread() is not threading.main_thread():
        yield seen
        return
    before = {s: signal.signal(s, handler) for s in (signal.SIGINT, signal.SIGTERM)}
    try:
        yield seen
    finally:
        for s, h in before.items():
            signal.signal(s, h)
