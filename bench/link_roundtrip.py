"""`{Q:P}` → C round trip with pacing off, over a pty and over TCP.

The board answers in its next 50 ms telemetry slot; what the link and the server add is
the time beyond that slot. The slot phase is read from the telemetry itself (each record
leaves at a slot time, and arrives with the same link delay as the C record).
Target: under 2 ms beyond the board's next slot.
"""

from __future__ import annotations

import argparse
import math
import random
import time

import appmode  # noqa: F401 - registers sim://
from appmode.ports.urls import open_link
from appmode.protocol.app import ParamsRecord
from appmode.protocol.app_decoders import BoardDecoder
from bench.common import board, summary_ms

SLOT = 0.05


def measure(url: str, trials: int, carried: float = 0.0) -> list[float]:
    """The time beyond the board's next slot; `carried`: the most a write may take to
    reach the board (a radio's connection event), whose slot is then the next one."""
    port = open_link(url, timeout=0.2)
    decoder = BoardDecoder()
    extra: list[float] = []
    last_record = None
    rng = random.Random(1)
    while len(extra) < trials:
        data = port.read(max(1, port.in_waiting))
        now = time.monotonic()
        records = decoder.feed(data)
        if not records:
            continue
        last_record = now
        time.sleep(rng.uniform(0.0, 0.045))
        sent = time.monotonic()
        port.write(b"{Q:P}")
        while True:
            data = port.read(max(1, port.in_waiting))
            got = time.monotonic()
            if any(isinstance(r, ParamsRecord) for r in decoder.feed(data)):
                break
        slots = math.ceil((sent + carried - last_record) / SLOT - 1e-9)
        next_slot = last_record + slots * SLOT
        extra.append(max(0.0, got - next_slot))
        decoder = BoardDecoder()
    port.close()
    return extra


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--trials", type=int, default=200)
    args = parser.parse_args()
    for label, option in (("pty", ("--pty",)), ("TCP", ("--listen", "0"))):
        with board(*option, "--no-pace") as url:
            extra = measure(url, args.trials)
        print(
            f"{{Q:P}} -> C over {label}, beyond the next slot: {summary_ms(extra)} (target < 2 ms)"
        )


if __name__ == "__main__":
    main()
