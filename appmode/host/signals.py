"""The signals that end a host session the way Ctrl-C does, the car stopped.

SIGTERM is a polite kill; SIGHUP is a closed terminal or a dropped SSH connection.
"""

from __future__ import annotations

import signal

ENDING_SIGNALS: tuple[signal.Signals, ...] = tuple(
    getattr(signal, name) for name in ("SIGTERM", "SIGHUP") if hasattr(signal, name)
)
