"""Decoder throughput on a 10 MB board stream with 1 % noise.

Side by side in one run: appmode's BoardDecoder, and a straightforward byte-at-a-time
decoder written the way the firmware's interrupt handler reads bytes (a handler called
per byte, a state machine, a buffer of digits), each the best of three runs taken in
turn. Both build every record, fully decoded to integers.
Target: at least 8 MB/s, and at least 2x the byte-at-a-time decoder.
"""

from __future__ import annotations

import argparse
import math
import random
import time
from collections.abc import Callable
from typing import Any

from appmode.protocol.app import RECORDS
from appmode.protocol.app_decoders import BoardDecoder
from tests.support.byte_loops import (
    DECODERS,
    SAME_EVENTS,
    ByteAtATime,
    check_same_events,
    make_stream,
    streams,
)


def timed(run: Callable[[], int]) -> tuple[float, int]:
    start = time.perf_counter()
    count = run()
    return time.perf_counter() - start, count


def best_of(runs: int, *decoders: Callable[[], int]) -> list[tuple[float, int]]:
    """Each decoder's best (seconds, count) of `runs` runs, taken in turn: a moment of the
    machine's load falls on one run, not on one decoder."""
    best = [(math.inf, 0)] * len(decoders)
    for _ in range(runs):
        best = [min(b, timed(run)) for b, run in zip(best, decoders, strict=True)]
    return best


def compare(megabytes: float, noise: float, chunk: int, runs: int = 3) -> dict[str, float]:
    """Both decoders on the same stream, the best of `runs` runs each: MB/s and records/s
    of each."""
    stream, _ = make_stream(int(megabytes * 1e6), noise)
    chunks = [stream[i : i + chunk] for i in range(0, len(stream), chunk)]

    def ours() -> int:
        decoder = BoardDecoder()
        return sum(isinstance(e, RECORDS) for c in chunks for e in decoder.feed(c))

    def naive() -> int:
        decoder = ByteAtATime()
        for piece in chunks:
            decoder.feed(piece)
        return len(decoder.records)

    (fast, fast_count), (slow, slow_count) = best_of(runs, ours, naive)
    return {
        "mb": len(stream) / 1e6,
        "ours_mbs": len(stream) / fast / 1e6,
        "ours_rps": fast_count / fast,
        "naive_mbs": len(stream) / slow / 1e6,
        "naive_rps": slow_count / slow,
        "speedup": slow / fast,
    }


GARBAGE_MB = 2.0


def garbage_inputs(megabytes: float = GARBAGE_MB) -> dict[str, bytes]:
    """Inputs a capture at the wrong baud rate (or a hostile one) looks like."""
    size = int(megabytes * 1e6)
    return {
        "random bytes": random.Random(3).randbytes(size),
        "only '{'": b"{" * size,
        "'{A' and one long digit run": b"{A" + b"1" * (size - 2),
    }


def garbage(megabytes: float = GARBAGE_MB, chunk: int = 4096) -> dict[str, float]:
    """MB/s of BoardDecoder and HostDecoder on each garbage input, fed in chunks: linear
    decoding keeps these near the clean stream's figure."""
    from appmode.protocol.app_decoders import HostDecoder

    rates = {}
    for name, data in garbage_inputs(megabytes).items():
        for side, make in (("board", BoardDecoder), ("host", HostDecoder)):
            decoder = make()
            start = time.perf_counter()
            for i in range(0, len(data), chunk):
                decoder.feed(data[i : i + chunk])
            decoder.flush()
            rates[f"{name}, {side} decoder"] = len(data) / (time.perf_counter() - start) / 1e6
    return rates


# ------------------------------------------------ every decoder against its byte loop


def _seconds(make: Callable[[], Any], data: bytes, chunk: int) -> float:
    decoder = make()
    start = time.perf_counter()
    for i in range(0, len(data), chunk):
        decoder.feed(data[i : i + chunk])
    return time.perf_counter() - start


def against_byte_loops(megabytes: float, chunk: int = 4096) -> dict[str, list[tuple[str, float]]]:
    """For each decoder: (input, its speed over its byte loop's) on every input, the best
    of three runs each."""
    inputs = streams(int(megabytes * 1e6))
    for name in SAME_EVENTS:
        for data in inputs.values():
            check_same_events(name, data, chunk)
    out: dict[str, list[tuple[str, float]]] = {}
    for name, (ours, loop) in DECODERS.items():
        out[name] = [
            (
                what,
                min(_seconds(loop, data, chunk) for _ in range(3))
                / min(_seconds(ours, data, chunk) for _ in range(3)),
            )
            for what, data in inputs.items()
        ]
    return out


def one_call(small: float = 4.0, large: float = 32.0) -> tuple[float, float]:
    """MB/s of one BoardDecoder.feed of a `small` and of a `large` MB stream, the better
    of two calls (the first call that needs the memory pays for the OS handing it over)."""
    rates = []
    for megabytes in (small, large):
        data, _ = make_stream(int(megabytes * 1e6), 0.01)
        best = math.inf
        for _ in range(2):
            start = time.perf_counter()
            events = BoardDecoder().feed(data)
            best = min(best, time.perf_counter() - start)
            del events
        rates.append(len(data) / best / 1e6)
    return rates[0], rates[1]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--megabytes", type=float, default=10.0)
    parser.add_argument("--noise", type=float, default=0.01)
    parser.add_argument("--chunk", type=int, default=4096, help="bytes per feed call")
    args = parser.parse_args()
    r = compare(args.megabytes, args.noise, args.chunk)
    print(
        f"{r['mb']:.1f} MB board stream, {args.noise:.0%} of bytes replaced by noise, fed in "
        f"{args.chunk}-byte chunks"
    )
    print(f"appmode BoardDecoder       {r['ours_mbs']:6.2f} MB/s {r['ours_rps']:10,.0f} records/s")
    print(
        f"byte-at-a-time (firmware)  {r['naive_mbs']:6.2f} MB/s {r['naive_rps']:10,.0f} records/s"
    )
    print(f"speed-up {r['speedup']:.1f}x (targets: >= 8 MB/s, >= 2x)")
    for name, rate in garbage().items():
        print(f"garbage, {GARBAGE_MB:.0f} MB of {name}: {rate:6.2f} MB/s")
    small, large = one_call()
    print(f"one feed() call: 4 MB at {small:.2f} MB/s, 32 MB at {large:.2f} MB/s")
    print("each decoder against its byte loop, 1 MB of each input (x = loop time / ours):")
    for name, rows in against_byte_loops(1.0).items():
        print(f"  {name}: " + ", ".join(f"{what} {x:.2f}x" for what, x in rows))


if __name__ == "__main__":
    main()
