"""What a UART makes of bytes sent at another bit rate, with no I/O.

A wrong baud rate is the commonest first fault of a serial link: a Bluetooth module set
to 38400, a terminal left at 115200. The receiver does not fail: it times each byte from
a falling edge at its own rate and hands over whatever it sampled, so a wrong rate reads
as bytes that are not records. `misread` is that receiver, bit by bit (8N1, the line idle
before and after `data`), for a simulated board served on a pseudo-terminal: a client
that opens it at the wrong rate hears what it would hear from a real UART.
"""

from __future__ import annotations

import math

BITS = 10
"""Bits on the line per byte: a start bit, 8 data bits (least significant first), a stop
bit."""


def misread(data: bytes, sent: int, read: int) -> bytes:
    """The bytes a UART reading at `read` bps takes from `data` sent back to back at
    `sent` bps. A byte whose stop bit samples low (a framing error) is handed over as
    sampled, as Linux does with input parity checks off (pyserial's setting)."""
    if sent == read or not data or sent <= 0 or read <= 0:
        return data
    line = bytearray()  # the sender's bit cells; past them the line is idle (1)
    for byte in data:
        line.append(0)
        line.extend((byte >> bit) & 1 for bit in range(8))
        line.append(1)
    total = len(line)
    ratio = sent / read  # one receiver bit in sender bit cells

    def level(cell: float) -> int:
        at = int(cell)
        return line[at] if at < total else 1

    out = bytearray()
    cell = line.find(0)  # where the receiver sees its next falling edge
    while cell != -1:
        if level(cell + ratio / 2) == 0:  # a start bit, not a glitch
            value = 0
            for bit in range(8):
                value |= level(cell + ratio * (bit + 1.5)) << bit
            out.append(value)
            after = max(cell + 1, math.ceil(cell + ratio * 9.5))  # past the stop sample
        else:
            after = cell + 1
        cell = _falling_edge(line, after)
    return bytes(out)


def _falling_edge(line: bytearray, start: int) -> int:
    """The first cell at or after `start` that is low after a high one (the line is high
    before cell 0), or -1."""
    while True:
        low = line.find(0, start)
        if low == -1 or low == 0 or line[low - 1] == 1:
            return low
        high = line.find(1, low)
        if high == -1:
            return -1
        start = high
