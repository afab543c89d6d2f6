"""A protocol-level RTDE test server: a UR controller's port 30004 on loopback, serving a log.

It speaks the controller's side of UR's published RTDE protocol, version 2, written here from
the protocol description and independently of :mod:`kinergy.live.rtde` (so a layout both got
wrong the same way is unlikely): every package is ``>HB`` (size including the header, type
letter) and a payload; ``V`` (protocol version) is answered ``>B`` accepted for version 2 only;
``v`` with ``>IIII``; ``O`` (``>d`` frequency + comma separated names) with ``>B`` recipe id 1
and the comma separated types (``NOT_FOUND`` for a name it does not know); ``S`` and ``P`` with
``>B`` 1; data packages ``U`` carry ``>B`` recipe id and the values, big-endian.

The controller's clock starts when the server starts and ticks at ``rate`` (500 Hz): package
``k`` has ``timestamp = t0 + k / rate`` and the log's row ``k mod N`` (the program repeats), so
a client connecting later starts at the current sample and samples missed while disconnected
are lost, as on a real controller. ``drop_after=K`` closes the first connection after K
packages and refuses connections for ``down_for`` seconds (a cable pulled and put back).

Run it by hand to try ``kinergy record`` or ``kinergy monitor`` without a robot::

    python tests/rtde_server.py --port 30004     # the UR5e twin running test A, forever
"""

from __future__ import annotations

import argparse
import select
import socket
import struct
import threading
import time
from typing import Any

import numpy as np

from kinergy.io.log import Log

#: The variables this controller knows: name -> (RTDE type, struct code, width)
VARIABLES = {
    "timestamp": ("DOUBLE", "d", 1),
    "target_q": ("VECTOR6D", "6d", 6),
    "target_qd": ("VECTOR6D", "6d", 6),
    "target_qdd": ("VECTOR6D", "6d", 6),
    "target_current": ("VECTOR6D", "6d", 6),
    "target_moment": ("VECTOR6D", "6d", 6),
    "actual_q": ("VECTOR6D", "6d", 6),
    "actual_qd": ("VECTOR6D", "6d", 6),
    "actual_current": ("VECTOR6D", "6d", 6),
    "joint_temperatures": ("VECTOR6D", "6d", 6),
    "actual_joint_voltage": ("VECTOR6D", "6d", 6),
    "actual_robot_voltage": ("DOUBLE", "d", 1),
    "actual_robot_current": ("DOUBLE", "d", 1),
    "robot_mode": ("INT32", "i", 1),
    "runtime_state": ("UINT32", "I", 1),
}
#: what the server serves for a known variable the log lacks
DEFAULTS = {"joint_temperatures": 32.5, "robot_mode": 7, "runtime_state": 2}
VERSION = (5, 21, 3, 1234)
T0 = 8642.25  # the controller's clock at the server's start, s (as if switched on earlier)


def _package(kind: str, payload: bytes = b"") -> bytes:
    return struct.pack(">HB", 3 + len(payload), ord(kind)) + payload


class RtdeServer:
    """A fake controller on ``127.0.0.1`` serving ``log`` over RTDE (see the module docstring).

    Use as a context manager; ``port`` is chosen by the system unless given.
    """

    def __init__(
        self,
        log: Log,
        *,
        rate: float = 500.0,
        port: int = 0,
        drop_after: int | None = None,
        down_for: float = 0.3,
    ) -> None:
        self.log = log
        self.rate = rate
        self.drop_after = drop_after
        self.down_for = down_for
        self.listener = socket.create_server(("127.0.0.1", port))
        self.port = self.listener.getsockname()[1]
        self.connections = 0
        self.sent = 0
        self.drops = 0
        self._down_until = 0.0
        self._stop = threading.Event()
        self._threads: list[threading.Thread] = []
        self._start = time.monotonic()

    @property
    def address(self) -> str:
        return f"127.0.0.1:{self.port}"

    def __enter__(self) -> RtdeServer:
        self._start = time.monotonic()
        # set here, not in the thread: a server left at once closes the listener before it runs
        self.listener.settimeout(0.05)
        accept = threading.Thread(target=self._accept, daemon=True)
        accept.start()
        self._threads.append(accept)
        return self

    def __exit__(self, *exc: Any) -> None:
        self._stop.set()
        self.listener.close()
        for t in self._threads:
            t.join(timeout=5.0)

    def now(self) -> int:
        """The controller's current sample index."""
        return int((time.monotonic() - self._start) * self.rate)

    def _accept(self) -> None:
        while not self._stop.is_set():
            try:
                sock, _ = self.listener.accept()
            except (TimeoutError, OSError):
                continue
            if time.monotonic() < self._down_until:
                sock.close()  # the network is down
                continue
            self.connections += 1
            handler = threading.Thread(target=self._serve, args=(sock,), daemon=True)
            handler.start()
            self._threads.append(handler)

    def _values(self, name: str, row: int, k: int) -> list[float | int]:
        kind, _code, width = VARIABLES[name]
        if name == "timestamp":
            return [T0 + k / self.rate]
        if name in self.log:
            raw = np.atleast_1d(self.log[name][row])
        else:
            raw = np.full(width, DEFAULTS.get(name, 0.0))
        if kind in ("INT32", "UINT32"):
            return [round(float(x)) for x in raw]
        return [float(x) for x in raw]

    def _serve(self, sock: socket.socket) -> None:
        session: dict[str, Any] = {"streaming": False, "next": 0, "sent": 0}
        buffer = b""
        try:
            while not self._stop.is_set():
                ready, _, _ = select.select([sock], [], [], 0.002)
                if ready:
                    chunk = sock.recv(4096)
                    if not chunk:
                        return
                    buffer += chunk
                    while len(buffer) >= 3:
                        size, kind = struct.unpack(">HB", buffer[:3])
                        if len(buffer) < size:
                            break
                        reply = self._answer(chr(kind), buffer[3:size], session)
                        buffer = buffer[size:]
                        if reply:
                            sock.sendall(reply)
                if session["streaming"] and not self._stream(sock, session):
                    return
        except OSError:
            return
        finally:
            sock.close()

    def _answer(self, kind: str, payload: bytes, session: dict[str, Any]) -> bytes:
        if kind == "V":
            (version,) = struct.unpack(">H", payload)
            return _package("V", struct.pack(">B", 1 if version == 2 else 0))
        if kind == "v":
            return _package("v", struct.pack(">IIII", *VERSION))
        if kind == "O":
            (frequency,) = struct.unpack(">d", payload[:8])
            names = payload[8:].decode("ascii").split(",")
            types = [VARIABLES[n][0] if n in VARIABLES else "NOT_FOUND" for n in names]
            ok = "NOT_FOUND" not in types
            session["names"] = names
            session["step"] = max(1, round(self.rate / frequency))
            session["layout"] = struct.Struct(
                ">B" + "".join(VARIABLES[n][1] for n in names if n in VARIABLES)
            )
            return _package("O", struct.pack(">B", 1 if ok else 0) + ",".join(types).encode())
        if kind == "S":
            session["streaming"] = True
            session["next"] = self.now()
            text = b"RTDE test server"
            source = b"kinergy-tests"
            message = bytes([len(text)]) + text + bytes([len(source)]) + source + b"\x01"
            return _package("S", b"\x01") + _package("M", message)
        if kind == "P":
            session["streaming"] = False
            return _package("P", b"\x01")
        return b""

    def _stream(self, sock: socket.socket, session: dict[str, Any]) -> bool:
        """Send the packages due; False when this connection is to be dropped."""
        now = self.now()
        out = []
        n = len(self.log)
        for k in range(session["next"], now + 1):
            if k % session["step"]:
                continue
            values: list[float | int] = []
            for name in session["names"]:
                values.extend(self._values(name, k % n, k))
            out.append(_package("U", session["layout"].pack(1, *values)))
            session["sent"] += 1
            if (
                self.drop_after is not None
                and self.drops == 0
                and session["sent"] >= self.drop_after
            ):
                sock.sendall(b"".join(out))
                self.sent += len(out)
                self.drops += 1
                self._down_until = time.monotonic() + self.down_for
                return False
        session["next"] = now + 1
        if out:
            sock.sendall(b"".join(out))
            self.sent += len(out)
        return True


def twin_log() -> Log:
    """The UR5e twin running the UR5e doc's test A (13.5 s at 500 Hz), realistic noise."""
    import kinergy
    from kinergy.trajectory.programs import paper_trajectory
    from kinergy.twin import TwinSettings, simulate

    robot = kinergy.load_robot("ur5e")
    return simulate(robot, paper_trajectory(robot, "test-a"), TwinSettings(seed=3))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--port", type=int, default=30004)
    parser.add_argument("--drop-after", type=int, default=None)
    args = parser.parse_args()
    with RtdeServer(twin_log(), port=args.port, drop_after=args.drop_after) as server:
        print(f"serving the UR5e twin on {server.address}; Ctrl-C stops", flush=True)
        try:
            while True:
                time.sleep(1.0)
        except KeyboardInterrupt:
            pass


if __name__ == "__main__":
    main()
