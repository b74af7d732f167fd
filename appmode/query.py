"""Parameter reads and verified sets as a state machine, with no I/O.

A ParamQuery sends `{Q:P}` (after `{n:v}` for a set), waits for a C record, resends on
timeout up to `tries` times, and ends in QueryDone or QueryFailed. A set is done only
when a C record read after it shows the value; a C record that was not received intact
never counts (the decoder reports it as malformed instead).
"""

from __future__ import annotations

from dataclasses import dataclass

from . import params, protocol

TIMEOUT = 0.5
TRIES = 3


@dataclass(frozen=True, slots=True)
class QueryDone:
    values: tuple[int, ...]
    text: str


@dataclass(frozen=True, slots=True)
class QueryFailed:
    text: str


Outcome = QueryDone | QueryFailed


class ParamQuery:
    """Read the parameters, or set one and verify it by reading back."""

    def __init__(
        self,
        change: tuple[int, int] | None = None,
        timeout: float = TIMEOUT,
        tries: int = TRIES,
        where: str = "the board",
    ) -> None:
        if change is not None:
            params.check_value(*change)
        self.change = change
        self.timeout = timeout
        self.tries = tries
        self.where = where
        self.sent = 0
        self.deadline = 0.0
        self._mismatch: int | None = None

    def _request(self, now: float) -> bytes:
        self.sent += 1
        self.deadline = now + self.timeout
        read = protocol.encode(protocol.ReadParams())
        if self.change is None:
            return read
        return protocol.encode(protocol.SetParam(*self.change)) + read

    def start(self, now: float) -> bytes:
        """The bytes to send first."""
        return self._request(now)

    def on_params(self, values: tuple[int, ...], now: float) -> tuple[bytes, Outcome | None]:
        """A C record arrived: (bytes to send, outcome or None)."""
        if self.change is None:
            return b"", QueryDone(values, "parameters read")
        index, value = self.change
        name = params.PARAMS[index].name
        if values[index] == value:
            return b"", QueryDone(values, f"{name} = {value} (verified)")
        self._mismatch = values[index]  # maybe a C record sent before the set: wait on
        return b"", None

    def on_time(self, now: float) -> tuple[bytes, Outcome | None]:
        """Call as time passes: a resend, a failure, or nothing yet."""
        if now < self.deadline:
            return b"", None
        return self._retry(now)

    def _retry(self, now: float) -> tuple[bytes, Outcome | None]:
        if self.sent < self.tries:
            return self._request(now), None
        if self.change is not None and self._mismatch is not None:
            index, value = self.change
            return b"", QueryFailed(
                f"{params.PARAMS[index].name} reads {self._mismatch} after setting it to "
                f"{value} {self.tries} times: the board did not take the value"
            )
        return b"", QueryFailed(
            f"no parameters from {self.where}: sent {{Q:P}} {self.tries} times and no C record "
            f"came back within {self.timeout:g} s; check the board is on, the port and baud "
            f"rate (9600), and that no other program is using the port"
        )
