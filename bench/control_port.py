"""The control port (UART2, docs/protocol.md §8–§12): decoder throughput, a read's round
trip over a pty, paced throughput at 115200 bps, and the CPU of a board serving both
ports with the encoder report on.

A read is answered in the board's next 10 ms control tick (§11), so its round trip is up
to 10 ms of waiting plus 1.4 ms of wire time (10 bytes in, 6 out). What the host can
improve is what comes beyond the tick: the reply's arrival is measured against the
board's 10 ms grid (its phase estimated from the earliest replies).
"""

from __future__ import annotations

import argparse
import itertools
import os
import random
import subprocess
import sys
import threading
import time
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

import serial

from appmode.protocol import control, control_decoders, settings
from appmode.protocol.params import DriveType
from bench.common import (
    Row,
    fitted_slope,
    floor_row,
    over_floor,
    over_floor_met,
    percentile,
    share_and_floor,
)

TICK = 0.010
BYTE = 10 / 115200
READ = control.encode(control.read("max_speed"))


@contextmanager
def served(
    *args: str, root: Path | None = None
) -> Iterator[tuple[subprocess.Popen[str], str, str]]:
    """`appmode board --pty ARGS` (from the appmode package in folder `root`, if given):
    the process, its APP port and its UART2."""
    proc = subprocess.Popen(
        [sys.executable, "-m", "appmode", "board", "--pty", "--quiet", *args],
        stdout=subprocess.PIPE,
        text=True,
        env=None if root is None else {**os.environ, "PYTHONPATH": str(root)},
        cwd=root,
    )
    try:
        assert proc.stdout is not None
        app, uart2 = (proc.stdout.readline() for _ in range(2))
        if not (app.startswith("port: ") and uart2.startswith("uart2: ")):
            raise SystemExit(f"appmode board {' '.join(args)} did not start (from {root or '.'})")
        yield proc, app.split(" ", 1)[1].strip(), uart2.split(" ", 1)[1].strip()
    finally:
        proc.terminate()
        proc.wait(10)


def decoder_rows(size: int) -> list[Row]:
    rng = random.Random(3)
    frames = [
        control.encode(control.velocity(DriveType.MECANUM, rng.randint(-500, 500), 300, 0))
        for _ in range(50)
    ] + [READ, control.encode(control.MotorFrame((1, -2, 3, -4)))]
    stream = b"".join(rng.choice(frames) for _ in range(size // 11))
    replies = control.encode(control.Reply(1, 500)) + control.encode(
        control.EncoderReport((1, 2, 3, 4), (5, 6, 7, 8))
    )
    board_stream = replies * (len(stream) // len(replies))
    rows = []
    for name, make, data in (
        ("host→board", lambda: control_decoders.FrameDecoder(DriveType.MECANUM), stream),
        ("board→host", control_decoders.ReplyDecoder, board_stream),
    ):
        start = time.perf_counter()
        decoder = make()
        for i in range(0, len(data), 4096):
            decoder.feed(data[i : i + 4096])
        whole = len(data) / (time.perf_counter() - start) / 1e6
        part = data[: len(data) // 10]
        start = time.perf_counter()
        decoder = make()
        for i in range(len(part)):
            decoder.feed(part[i : i + 1])
        single = len(part) / (time.perf_counter() - start) / 1e6
        rows.append(
            Row(
                f"UART2 decoder, {name}",
                f"{whole:.1f} MB/s in 4 KiB reads; {single:.2f} MB/s a byte at a time "
                f"({whole / single:.0f}x)",
                "≫ 11,520 bytes/s (4 KiB reads >= 100x)",
                whole * 1e6 >= 100 * 11520,
            )
        )
    return rows


def round_trip_rows(trials: int) -> list[Row]:
    with served() as (_, _, uart2), serial.Serial(uart2, 115200, timeout=1) as port:
        arrivals, trips = [], []
        rng = random.Random(5)
        for _ in range(trials):
            time.sleep(rng.uniform(0.002, 0.03))
            start = time.monotonic()
            port.write(READ)
            got = b""
            while len(got) < 6:
                got += port.read(6 - len(got))
            end = time.monotonic()
            assert got == bytes.fromhex("23 01 00 00 01 F4"), got
            trips.append(end - start)
            arrivals.append(end)
    wire_out = 6 * BYTE
    phases = sorted((a - wire_out) % TICK for a in arrivals)
    # the board's tick phase: where the replies' phases begin, after the widest gap
    gaps = [(b - a, b) for a, b in itertools.pairwise(phases)]
    gaps.append((phases[0] + TICK - phases[-1], phases[0]))
    phase = max(gaps)[1]
    beyond = [((a - wire_out - phase) % TICK) * 1000 for a in arrivals]
    trip_ms = [t * 1000 for t in trips]
    next_tick = (TICK + len(READ) * BYTE + wire_out) * 1000 + 2
    return [
        Row(
            "UART2 read round trip over a pty (FF FE 80 80 11 … → 23 01 …)",
            f"median {percentile(trip_ms, 50):.2f} ms, p99 {percentile(trip_ms, 99):.2f} ms "
            f"(n={trials}; includes the wait for the next 10 ms tick)",
            f"answered in the next tick (p99 < {next_tick:.1f} ms: a tick, the wire, 2 ms)",
            percentile(trip_ms, 99) < next_tick,
        ),
        Row(
            "UART2 reply beyond its tick (the reply's 0.52 ms of wire excluded)",
            f"median {percentile(beyond, 50):.2f} ms, p99 {percentile(beyond, 99):.2f} ms",
            "p99 < 2 ms",
            percentile(beyond, 99) < 2,
        ),
    ]


def throughput_rows(frames: int) -> list[Row]:
    """Reads written back to back: the board takes them at the line rate and answers each
    in the tick after it arrives. The replies' arrival between the 10th and the 90th
    percent of them gives the rate the input moved at: the slope of replies over their
    arrival (least squares), which the 10 ms steps of the ticks do not bend as they do a
    count divided by the time between two replies."""
    with served() as (_, _, uart2), serial.Serial(uart2, 115200, timeout=2) as port:
        writer = threading.Thread(target=port.write, args=(READ * frames,))
        writer.start()  # the write blocks while the board holds the line back
        times: list[float] = []
        got = b""
        while len(got) < 6 * frames:
            chunk = port.read(max(1, min(port.in_waiting, 6 * frames - len(got))))
            if not chunk:
                raise SystemExit("replies stopped")
            now = time.monotonic()
            before = len(got) // 6
            got += chunk
            times += [now] * (len(got) // 6 - before)
        writer.join()
    assert got == bytes.fromhex("23 01 00 00 01 F4") * frames
    first, last = frames // 10, frames * 9 // 10
    slope, error = fitted_slope(times[first:last], range(first, last))
    rate, error = slope * len(READ), error * len(READ)
    return [
        Row(
            f"UART2 paced input, {frames:,} reads back to back",
            f"{rate / 11520 * 100:.3f} % (±{error / 11520 * 100:.3f}) of 11,520 bytes/s "
            f"(slope of replies over time), all {frames:,} answered",
            "≥ 99.5 %, never above 100 % (within its standard error)",
            rate >= 0.995 * 11520 and rate - error <= 11520,
        )
    ]


def drive_reporting(port: serial.Serial) -> None:
    """Over a mecanum board's UART2: the encoder report on, the car driving forward."""
    port.write(control.encode(control.SetSetting(settings.BY_NAME["system_mode"], 0x41)))
    port.write(control.encode(control.velocity(DriveType.MECANUM, y=200)))


def cpu_rows(seconds: float) -> list[Row]:
    with (
        served("--drive", "mecanum") as (proc, app, uart2),
        serial.Serial(uart2, 115200, timeout=0.1) as port,
        serial.Serial(app, 9600, timeout=0.1) as app_port,
    ):
        drive_reporting(port)
        time.sleep(0.5)
        cpu = share_and_floor(
            proc.pid,
            seconds,
            lambda: len(port.read(port.in_waiting)) + len(app_port.read(app_port.in_waiting)),
        )
        port.write(control.STOP)
    return [
        Row(
            "board serving both ports, encoder report on (mecanum, driving)",
            f"{cpu.share:.2f} % of a core ({cpu.received:,.0f} bytes/s read from both ports); "
            f"{over_floor(cpu)}",
            "< 2 % of a core; within 0.3 % of its floor",
            cpu.share < 2 and over_floor_met(cpu),
        ),
        floor_row(cpu),
    ]


def rows(quick: bool) -> list[Row]:
    return [
        *decoder_rows(1_000_000 if quick else 4_000_000),
        *round_trip_rows(200 if quick else 1000),
        *throughput_rows(2000 if quick else 10_000),
        *cpu_rows(12 if quick else 120),
    ]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--quick", action="store_true", help="shorter runs")
    args = parser.parse_args()
    for row in rows(args.quick):
        print(f"| {row.benchmark} | {row.result} | {row.target} | {row.met} |")


if __name__ == "__main__":
    main()
