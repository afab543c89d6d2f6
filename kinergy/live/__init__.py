"""Live data from a robot controller: the RTDE protocol, recording to files, monitoring energy.

- :mod:`kinergy.live.rtde`: UR's RTDE protocol (version 2), the handshake and data packages;
- :mod:`kinergy.live.stream`: every package on a reader thread, reconnecting when dropped;
- :mod:`kinergy.live.recorder`: packages to record.py-layout files (segments, rotation);
- :mod:`kinergy.live.monitor`: energy per program cycle, measured against the model.
"""

__all__: list[str] = []
