"""Paced throughput of `appmode board --pty` as a fraction of 960 bytes/s.

The board's output is saturated by asking for a long C record (all Kp/Ki/Kd at their
maximum: about 100 bytes) in every 50 ms slot, twice what the line carries. A client
counts the bytes it receives over the window; the rate is the slope of the bytes received
against the time each read returned (least squares), so that a read that returns late
(the client was not scheduled at once) does not bend it, as it would a count divided by
the time between two reads. Target: at least 99.5 %, never above 100 %.
"""

from __future__ import annotations

import argparse
import time

import serial

from bench.common import board, fitted_slope

LINE_RATE = 960.0


def measure(seconds: float) -> tuple[float, float]:
    """Bytes a second a client receives from a saturated, paced board over a pty, and the
    fit's standard error."""
    with board("--pty") as url:
        port = serial.Serial(url, 9600, timeout=0.01)
        port.write(b"".join(b"{%d:4294967295}" % n for n in range(2, 8)))
        next_ask = time.monotonic()
        start = None
        received = 0
        times: list[float] = []
        totals: list[float] = []
        warmup = time.monotonic() + 1.0
        while True:
            now = time.monotonic()
            if now >= next_ask:
                port.write(b"{Q:P}")
                next_ask += 0.025
            data = port.read(4096)
            now = time.monotonic()
            if now < warmup or not data:
                continue
            if start is None:
                start = now
            received += len(data)
            times.append(now - start)
            totals.append(received)
            if now - start >= seconds:
                break
        port.close()
    return fitted_slope(times, totals)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--seconds", type=float, default=10.0, help="measuring window")
    args = parser.parse_args()
    rate, error = measure(args.seconds)
    print(
        f"paced throughput over a pty: {rate:.2f} bytes/s (±{error:.2f}) over "
        f"{args.seconds:.0f} s = {rate / LINE_RATE * 100:.3f} % of {LINE_RATE:.0f} bytes/s "
        "(target >= 99.5 %, <= 100 %)"
    )


if __name__ == "__main__":
    main()
