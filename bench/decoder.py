"""Decoder throughput on a 10 MB board stream with 1 % noise.

Side by side in one run: appmode's BoardDecoder, and a straightforward byte-at-a-time
decoder written the way the firmware's interrupt handler reads bytes (a handler called
per byte, a state machine, a buffer of digits). Both build every record, fully decoded
to integers.
Target: at least 8 MB/s, and at least 2x the byte-at-a-time decoder.
"""

from __future__ import annotations

import argparse
import random
import time

from appmode.protocol.app import RECORDS, Attitude, BoardDecoder, ParamsRecord, Velocity, encode


def make_stream(size: int, noise: float, seed: int = 1) -> tuple[bytes, int]:
    """A board stream like the real one (A/B alternating, a C now and then), with noise."""
    rng = random.Random(seed)
    parts = []
    total = records = 0
    k = 0
    while total < size:
        if k % 50 == 49:
            record = encode(ParamsRecord((500, 10000, 20, 0, 10, 10, 10, 0, 1)))
        elif k % 2:
            record = encode(
                Attitude(
                    rng.randint(-9, 9),
                    rng.randint(-9, 9),
                    rng.randint(-179, 180),
                    rng.randint(0, 100),
                )
            )
        else:
            record = encode(
                Velocity(rng.randint(-600, 600), rng.randint(-600, 600), rng.randint(-600, 600), 0)
            )
        k += 1
        data = bytearray(record)
        for i in range(len(data)):
            if rng.random() < noise:
                data[i] = rng.randrange(256)
        parts.append(bytes(data))
        total += len(data)
        records += 1
    return b"".join(parts), records


class ByteAtATime:
    """The firmware's way: a handler called once per received byte (as the UART interrupt
    is), a small state machine, digits gathered into ints; records built like appmode's."""

    def __init__(self) -> None:
        self.in_record = False
        self.letter = 0
        self.fields: list[int] = []
        self.digits = bytearray()
        self.records: list[object] = []

    def feed(self, data: bytes) -> None:
        for byte in data:
            self.on_byte(byte)

    def on_byte(self, byte: int) -> None:
        if byte == 0x7B:  # '{'
            self.in_record, self.letter, self.fields = True, 0, []
            self.digits.clear()
        elif not self.in_record:
            return
        elif self.letter == 0:
            self.letter = byte
        elif byte == 0x3A or byte == 0x7D:  # ':' or '}'
            try:
                self.fields.append(int(self.digits))
            except ValueError:
                self.in_record = False
                return
            self.digits.clear()
            if byte == 0x7D:
                self.in_record = False
                self._record()
        elif byte == 0x2D or 0x30 <= byte <= 0x39:
            self.digits.append(byte)
        else:
            self.in_record = False

    def _record(self) -> None:
        fields = self.fields
        if self.letter == 0x41 and len(fields) == 4:
            self.records.append(Velocity(*fields))
        elif self.letter == 0x42 and len(fields) == 4:
            self.records.append(Attitude(*fields))
        elif self.letter == 0x43 and len(fields) == 9:
            self.records.append(ParamsRecord(tuple(fields)))


def timed(run: object) -> tuple[float, int]:
    start = time.perf_counter()
    count = run()  # type: ignore[operator]
    return time.perf_counter() - start, count


def compare(megabytes: float, noise: float, chunk: int) -> dict[str, float]:
    """Both decoders on the same stream: MB/s and records/s of each."""
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

    fast, fast_count = timed(ours)
    slow, slow_count = timed(naive)
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
    from appmode.protocol.app import HostDecoder

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


if __name__ == "__main__":
    main()
