"""UR's Real-Time Data Exchange (RTDE) protocol, version 2, client side.

A controller listens on TCP port 30004. Every package, both ways, is a big-endian header
``>HB`` (the package's whole size in bytes, header included; its type as one ASCII letter)
followed by its payload:

==========================  ====  =====================================  ==========================
package                     type  client sends                           controller answers
==========================  ====  =====================================  ==========================
request protocol version    ``V``  ``>H`` version (2)                    ``>B`` accepted
get controller version      ``v``  nothing                               ``>IIII`` major .. build
setup outputs               ``O``  ``>d`` frequency, then the variable   ``>B`` recipe id, then the
                                   names comma separated (ASCII)         types comma separated
start                       ``S``  nothing                               ``>B`` accepted
pause                       ``P``  nothing                               ``>B`` accepted
data package                ``U``  --                                    ``>B`` recipe id, values
text message                ``M``  --                                    ``>B`` n, text, ``>B`` n,
                                                                         source, ``>B`` level
==========================  ====  =====================================  ==========================

A data package holds the recipe's values in order, each packed by its type (:data:`TYPES`):
``DOUBLE`` as ``>d``, ``VECTOR6D`` as six ``>d``, ``INT32`` as ``>i``, ``UINT32`` as ``>I`` and so on;
an unknown variable comes back as type ``NOT_FOUND``.

:class:`Connection` speaks the handshake and reads data packages; :mod:`kinergy.live.stream`
reads them on a thread of its own into a queue as they arrive, so none is lost while the caller
writes a file.
"""

from __future__ import annotations

import contextlib
import socket
import struct
from collections.abc import Callable, Sequence
from dataclasses import dataclass

from kinergy.errors import KinergyError

__all__ = [
    "DEFAULT_PORT",
    "PROTOCOL_VERSION",
    "TYPES",
    "Connection",
    "Recipe",
    "parse_address",
]

DEFAULT_PORT = 30004
PROTOCOL_VERSION = 2

#: RTDE type name -> (struct code of its values, number of values)
TYPES: dict[str, tuple[str, int]] = {
    "BOOL": ("?", 1),
    "UINT8": ("B", 1),
    "UINT32": ("I", 1),
    "UINT64": ("Q", 1),
    "INT32": ("i", 1),
    "DOUBLE": ("d", 1),
    "VECTOR3D": ("3d", 3),
    "VECTOR6D": ("6d", 6),
    "VECTOR6INT32": ("6i", 6),
    "VECTOR6UINT32": ("6I", 6),
}

_HEADER = struct.Struct(">HB")
_REQUEST_PROTOCOL_VERSION = ord("V")
_GET_URCONTROL_VERSION = ord("v")
_TEXT_MESSAGE = ord("M")
_DATA_PACKAGE = ord("U")
_SETUP_OUTPUTS = ord("O")
_START = ord("S")
_PAUSE = ord("P")


def parse_address(address: str) -> tuple[str, int]:
    """``HOST[:PORT]`` as (host, port), port :data:`DEFAULT_PORT` when not given.

    An IPv6 address goes in brackets: ``[::1]:30004``.
    """
    text = address.strip()
    host, port = text, str(DEFAULT_PORT)
    if text.startswith("["):
        host, _, rest = text[1:].partition("]")
        if rest.startswith(":"):
            port = rest[1:]
        elif rest:
            raise KinergyError(f"bad address {address!r}: expected [HOST]:PORT")
    elif text.count(":") == 1:
        host, _, port = text.partition(":")
    if not host or not port.isdigit() or not 0 < int(port) < 65536:
        raise KinergyError(f"bad address {address!r}: expected HOST or HOST:PORT (port 1-65535)")
    return host, int(port)


@dataclass(frozen=True)
class Recipe:
    """An output recipe the controller accepted.

    Attributes
    ----------
    id : int
        The recipe id data packages carry.
    names : tuple of str
        The variables, in package order.
    types : tuple of str
        Their RTDE types (:data:`TYPES`).
    """

    id: int
    names: tuple[str, ...]
    types: tuple[str, ...]

    @property
    def layout(self) -> struct.Struct:
        """The struct of a data package's payload after the recipe id."""
        return struct.Struct(">" + "".join(TYPES[t][0] for t in self.types))

    @property
    def widths(self) -> tuple[int, ...]:
        """Values per variable (6 for a ``VECTOR6D``)."""
        return tuple(TYPES[t][1] for t in self.types)


class Connection:
    """One TCP connection to a controller's RTDE server, for the handshake.

    Parameters
    ----------
    host : str
    port : int
    timeout : float
        Seconds to wait for the connection and for each answer.
    on_text : callable, optional
        Receives the controller's text messages (``"source: text"``).
    """

    def __init__(
        self,
        host: str,
        port: int,
        *,
        timeout: float = 3.0,
        on_text: Callable[[str], None] | None = None,
    ) -> None:
        self.address = f"{host}:{port}"
        self.on_text = on_text
        self._buffer = bytearray()
        try:
            self.sock = socket.create_connection((host, port), timeout=timeout)
        except socket.gaierror:
            raise KinergyError(f"cannot resolve host {host!r}") from None
        except TimeoutError:
            raise KinergyError(f"cannot connect to {self.address}: timed out") from None
        except OSError as exc:
            reason = exc.strerror or str(exc)
            raise KinergyError(f"cannot connect to {self.address}: {reason}") from None
        self.sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)

    def close(self) -> None:
        """Close the connection; a thread blocked reading it wakes up with an error."""
        with contextlib.suppress(OSError):
            self.sock.shutdown(socket.SHUT_RDWR)
        with contextlib.suppress(OSError):
            self.sock.close()

    # -- packages -------------------------------------------------------------------------------

    def send(self, kind: int, payload: bytes = b"") -> None:
        """Send one package of type ``kind``."""
        self.sock.sendall(_HEADER.pack(_HEADER.size + len(payload), kind) + payload)

    def receive(self) -> tuple[int, bytes]:
        """The next package from the controller: (type, payload).

        Raises
        ------
        ConnectionError
            The controller closed the connection.
        TimeoutError
            Nothing arrived within the timeout.
        """
        while True:
            if len(self._buffer) >= _HEADER.size:
                size, kind = _HEADER.unpack_from(self._buffer)
                if size < _HEADER.size:
                    raise ConnectionError(f"a malformed package (size {size})")
                if len(self._buffer) >= size:
                    payload = bytes(self._buffer[_HEADER.size : size])
                    del self._buffer[:size]
                    return kind, payload
            chunk = self.sock.recv(1 << 16)
            if not chunk:
                raise ConnectionError("the controller closed the connection")
            self._buffer += chunk

    def _answer(self, kind: int) -> bytes:
        """The payload of the next package of type ``kind`` (text messages passed on, data
        packages of an earlier start skipped)."""
        while True:
            got, payload = self.receive()
            if got == kind:
                return payload
            if got == _TEXT_MESSAGE:
                self.text_message(payload)

    def text_message(self, payload: bytes) -> None:
        """Pass a text message package's payload on to ``on_text`` (protocol 2 layout)."""
        if self.on_text is None or not payload:
            return
        n = payload[0]
        text = payload[1 : 1 + n].decode("utf-8", "replace")
        m = payload[1 + n] if len(payload) > 1 + n else 0
        source = payload[2 + n : 2 + n + m].decode("utf-8", "replace")
        self.on_text(f"{source}: {text}" if source else text)

    # -- handshake ------------------------------------------------------------------------------

    def negotiate(self) -> tuple[int, int, int, int]:
        """Ask for protocol version 2; return the controller's version (major, minor, bugfix,
        build)."""
        self.send(_REQUEST_PROTOCOL_VERSION, struct.pack(">H", PROTOCOL_VERSION))
        if not struct.unpack(">B", self._answer(_REQUEST_PROTOCOL_VERSION)[:1])[0]:
            raise KinergyError(f"{self.address}: the controller refuses RTDE protocol version 2")
        self.send(_GET_URCONTROL_VERSION)
        major, minor, bugfix, build = struct.unpack(">IIII", self._answer(_GET_URCONTROL_VERSION))
        return major, minor, bugfix, build

    def setup_outputs(self, names: Sequence[str], frequency: float) -> tuple[int, list[str]]:
        """Send an output recipe; return (recipe id, the types the controller gave back)."""
        text = ",".join(names).encode("ascii")
        self.send(_SETUP_OUTPUTS, struct.pack(">d", float(frequency)) + text)
        payload = self._answer(_SETUP_OUTPUTS)
        types = payload[1:].decode("ascii", "replace").split(",")
        if len(types) != len(names):
            raise KinergyError(
                f"{self.address}: the controller answered {len(types)} types for "
                f"{len(names)} variables"
            )
        return payload[0], types

    def subscribe(
        self, names: Sequence[str], frequency: float, *, optional: Sequence[str] = ()
    ) -> Recipe:
        """Set up an output recipe of ``names`` at ``frequency`` Hz and start the stream.

        Variables in ``optional`` that the controller does not know (``NOT_FOUND``, an older
        software version) are left out and the recipe is sent again; an unknown required
        variable is an error.
        """
        recipe_id, types = self.setup_outputs(names, frequency)
        missing = [n for n, t in zip(names, types, strict=True) if t == "NOT_FOUND"]
        required = [n for n in missing if n not in optional]
        if required:
            raise KinergyError(
                f"{self.address}: the controller does not know {', '.join(required)}"
            )
        if missing:
            names = [n for n in names if n not in missing]
            recipe_id, types = self.setup_outputs(names, frequency)
        unknown = sorted({t for t in types if t not in TYPES})
        if unknown or recipe_id == 0:
            why = f"types {', '.join(unknown)}" if unknown else "recipe id 0"
            raise KinergyError(f"{self.address}: the controller refused the recipe ({why})")
        self.send(_START)
        if not self._answer(_START)[:1] == b"\x01":
            raise KinergyError(f"{self.address}: the controller refused to start the stream")
        return Recipe(recipe_id, tuple(names), tuple(types))

    def next_data(self, recipe: Recipe, layout: struct.Struct) -> tuple[float | int, ...]:
        """The values of the next data package of ``recipe`` (``layout`` = ``recipe.layout``),
        flat: a ``VECTOR6D`` gives six. Text messages on the way are passed on.

        Raises
        ------
        ConnectionError
            Closed, or a data package of the wrong size.
        TimeoutError
            Nothing arrived within the timeout.
        """
        while True:
            kind, payload = self.receive()
            if kind == _DATA_PACKAGE:
                if len(payload) != layout.size + 1:
                    raise ConnectionError(
                        f"a data package of {len(payload)} bytes, expected {layout.size + 1}"
                    )
                if payload[0] == recipe.id:
                    return layout.unpack_from(payload, 1)
            elif kind == _TEXT_MESSAGE:
                self.text_message(payload)

    def pause(self) -> None:
        """Ask the controller to stop sending (best effort: the connection may be gone)."""
        with contextlib.suppress(OSError):
            self.send(_PAUSE)
