"""Transcripts, format v1 (design.md): one protocol unit a line, `TIME DIR PAYLOAD`."""

from __future__ import annotations

import os
from typing import TextIO

from . import protocol
from .errors import AppmodeError
from .escaping import escape

HEADER = "# appmode transcript v1"
SUFFIX = ".transcript"


class Recorder:
    """Writes a session as it happens: each direction split into commands and records.

    Call it as a tap: `recorder(direction, time, data)` with `>` for host→board bytes and
    `<` for board→host bytes. Every line is flushed as it is written.
    """

    def __init__(self, out: TextIO, origin: float = 0.0) -> None:
        self._out = out
        self._origin = origin
        self._decoders: dict[str, protocol.HostDecoder | protocol.BoardDecoder] = {
            ">": protocol.HostDecoder(),
            "<": protocol.BoardDecoder(),
        }
        self._last = {">": origin, "<": origin}
        out.write(HEADER + "\n")
        out.flush()

    @classmethod
    def create(cls, path: str | os.PathLike[str], origin: float = 0.0) -> Recorder:
        try:
            out = open(path, "w", encoding="utf-8")  # noqa: SIM115 - owned by the recorder
        except OSError as exc:
            raise AppmodeError(
                f"cannot write transcript {os.fspath(path)}: {exc.strerror}"
            ) from None
        return cls(out, origin)

    def __call__(self, direction: str, time: float, data: bytes) -> None:
        self._last[direction] = time
        for event in self._decoders[direction].feed(data):
            self._line(time, direction, event.raw)

    def _line(self, time: float, direction: str, raw: bytes) -> None:
        self._out.write(f"{max(0.0, time - self._origin):.3f} {direction} {escape(raw)}\n")
        self._out.flush()

    def close(self) -> None:
        """Write what the decoders still hold, and close the file."""
        if self._out.closed:
            return
        for direction, decoder in self._decoders.items():
            for event in decoder.flush():
                self._line(self._last[direction], direction, event.raw)
        self._out.close()
