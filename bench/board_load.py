"""What serving and driving boards costs: CPU of `appmode board` and `appmode drive`,
boards one process serves, board-model steps, the console's key-to-byte latency, 60 s
floods, a trickle of bytes (`python -m bench.run_all` runs them)."""

from __future__ import annotations

import contextlib
import io
import os
import random
import select
import shutil
import statistics
import subprocess
import sys
import tempfile
import threading
import time
import tty
from collections.abc import Callable
from pathlib import Path

import serial

from appmode.board.firmware import TICK, Board
from appmode.testing.process import BoardProcess
from bench import (
    many_boards,
)
from bench.common import (
    Row,
    cpu_seconds,
    floor_row,
    over_floor,
    over_floor_met,
    percentile,
    share_and_floor,
)

TICKS = os.sysconf("SC_CLK_TCK")
FLAT_MIB = 4.0
"""Growth of a flooded board's memory (RSS) that still counts as flat."""


def rss_mib(pid: int) -> float:
    for line in Path(f"/proc/{pid}/status").read_text().splitlines():
        if line.startswith("VmRSS:"):
            return int(line.split()[1]) / 1024
    return 0.0


def start_board(*args: str) -> tuple[subprocess.Popen[str], list[str]]:
    """`appmode board --quiet ARGS`: its process and every board's APP port."""
    board = BoardProcess("--quiet", *args)
    return board.proc, board.urls


def stop(proc: subprocess.Popen[str]) -> None:
    proc.terminate()
    proc.wait(10)


def open_raw(path: str) -> int:
    fd = os.open(path, os.O_RDWR | os.O_NOCTTY | os.O_NONBLOCK)
    tty.setraw(fd)
    return fd


def bench_board_cpu(seconds: float) -> list[Row]:
    proc, [url] = start_board("--pty")
    fd = open_raw(url)

    def read() -> int:
        with contextlib.suppress(BlockingIOError):
            return len(os.read(fd, 4096))
        return 0

    try:
        time.sleep(1.0)
        cpu = share_and_floor(proc.pid, seconds, read)
    finally:
        os.close(fd)
        stop(proc)
    return [
        Row(
            "appmode board streaming telemetry (paced)",
            f"{cpu.share:.2f} % of a core ({cpu.received:.0f} bytes/s out); {over_floor(cpu)}",
            "< 1 %; within 0.3 % of its floor",
            cpu.share < 1 and over_floor_met(cpu),
        ),
        floor_row(cpu),
    ]


def bench_drive_cpu(seconds: float) -> list[Row]:
    if shutil.which("tmux") is None:
        return [
            Row("appmode drive showing telemetry", "not measured: tmux missing", "< 3 %", False)
        ]
    proc, [url] = start_board("--pty")
    session = "appmode-bench"
    try:
        subprocess.run(
            [
                "tmux",
                "new-session",
                "-d",
                "-s",
                session,
                "-x",
                "120",
                "-y",
                "40",
                f"exec {sys.executable} -m appmode drive {url}",
            ],
            check=True,
        )
        time.sleep(2.0)
        pid = int(
            subprocess.run(
                ["tmux", "display-message", "-p", "-t", session, "#{pane_pid}"],
                capture_output=True,
                text=True,
                check=True,
            ).stdout
        )
        start_cpu, start = cpu_seconds(pid), time.monotonic()
        time.sleep(seconds)
        share = (cpu_seconds(pid) - start_cpu) / (time.monotonic() - start) * 100
    finally:
        subprocess.run(["tmux", "kill-session", "-t", session], capture_output=True, check=False)
        stop(proc)
    return [
        Row(
            "appmode drive showing telemetry (tmux)", f"{share:.2f} % of a core", "< 3 %", share < 3
        )
    ]


def bench_many_boards(counts: list[int], seconds: float) -> list[Row]:
    rows = []
    read_share: dict[int, float] = {}
    for count in counts:
        r = many_boards.measure(count, seconds)
        read_share[count] = r["share"]
        rows.append(
            Row(
                f"{count} boards in one process, on ptys",
                f"{r['share']:.1f} % of a core; records/s per board min {r['min']:.1f}, "
                f"median {r['median']:.1f}; grid lateness p99 {r['p99']:.2f} ms",
                "1,000 boards within one core at 20/s, grid p99 < 5 ms",
                r["min"] >= 19.5 and r["p99"] < 5 and (count < 1000 or r["share"] < 100),
            )
        )
    r = many_boards.measure(200, seconds, read=False)
    rows.append(
        Row(
            "200 boards nobody reads (their ptys full)",
            f"{r['share']:.1f} % of a core; grid lateness p99 {r['p99']:.2f} ms",
            "no more than 200 boards that are read",
            None if 200 not in read_share else r["share"] <= read_share[200] * 1.1,
        )
    )
    return rows


def bench_model_steps() -> list[Row]:
    board = Board()
    board.receive(b"KC", 0.0)
    seconds = 2000.0
    start = time.perf_counter()
    for k in range(1, int(seconds / 0.5) + 1):
        board.poll(k * 0.5)
    elapsed = time.perf_counter() - start
    steps = seconds / TICK / elapsed
    return [Row("board model", f"{steps:,.0f} steps/s ({steps * TICK:,.0f}x real time)", "", None)]


def bench_key_latency(keys: int) -> list[Row]:
    from prompt_toolkit.input import create_pipe_input
    from prompt_toolkit.output import DummyOutput

    from appmode.console.driving import run_drive
    from appmode.ports.choice import choose
    from appmode.ports.target import parse_target
    from appmode.session.app.session import AppSession
    from appmode.session.hold import HoldToDrive

    sent: list[float] = []
    typed: list[float] = []
    session = AppSession(choose(parse_target("sim://?pace=0")), HoldToDrive(latched=True))
    real_send = session.host.send

    def send(data: bytes, still: Callable[[], bool] | None = None) -> None:
        if data in (b"A", b"Z"):
            sent.append(time.perf_counter())
        real_send(data, still)

    session.host.send = send  # type: ignore[method-assign]
    with create_pipe_input() as pipe:

        def typist() -> None:
            time.sleep(1.0)
            sent.clear()
            for k in range(keys):
                typed.append(time.perf_counter())
                pipe.send_text("w" if k % 2 == 0 else " ")
                time.sleep(0.02)
            time.sleep(0.3)
            pipe.send_text("\x03")

        thread = threading.Thread(target=typist, daemon=True)
        thread.start()
        run_drive(session, True, [], io.StringIO(), pipe, DummyOutput())
        thread.join()
    latency = [(s - t) * 1000 for t, s in zip(typed, sent, strict=False)]
    p99 = percentile(latency, 99)
    return [
        Row(
            "console key-to-byte latency",
            f"median {statistics.median(latency):.2f} ms, p99 {p99:.2f} ms (n={len(latency)})",
            "p99 < 5 ms",
            p99 < 5,
        )
    ]


def bench_flood(seconds: float, paced: bool, garbage: bool) -> Row:
    with tempfile.TemporaryDirectory() as tmp:
        record = Path(tmp) / "b.transcript"
        args = ["--pty"] + ([] if paced else ["--no-pace"])
        if not garbage:
            args += ["--record", str(record)]
        proc, [url] = start_board(*args)
        rng = random.Random(1)
        written = [0]
        stop_at = time.monotonic() + seconds

        def writer() -> None:
            port = serial.Serial(url, 9600, write_timeout=None)
            try:
                while time.monotonic() < stop_at:
                    if garbage:
                        port.write(rng.randbytes(512))
                    else:
                        port.write(b"{7:%d}" % (written[0] % 100000))
                    written[0] += 1
            except (serial.SerialException, OSError):
                pass

        time.sleep(0.5)
        before = rss_mib(proc.pid)
        thread = threading.Thread(target=writer, daemon=True)
        thread.start()
        time.sleep(seconds)
        after = rss_mib(proc.pid)
        stop(proc)
        thread.join(5)
        what = "garbage" if garbage else "valid commands"
        label = f"flood of {what}, {seconds:.0f} s, {'paced' if paced else 'no pacing'}"
        memory = f"RSS {before:.1f} -> {after:.1f} MiB"
        flat = after - before < FLAT_MIB
        if garbage:
            return Row(
                label,
                f"{written[0] * 512 / seconds / 1e3:,.0f} KB/s in; {memory}",
                f"memory flat (grows < {FLAT_MIB} MiB)",
                flat,
            )
        lines = [line.split(" ", 2)[2] for line in record.read_text().splitlines() if " > " in line]
        if lines and not lines[-1].endswith("}"):
            lines.pop()
        in_order = lines == [f"{{7:{k % 100000}}}" for k in range(len(lines))]
        return Row(
            label,
            f"{len(lines) / seconds:,.0f} commands/s applied, "
            f"{'all in order' if in_order else 'OUT OF ORDER'}; {memory}",
            f"all applied in order, memory flat (grows < {FLAT_MIB} MiB)",
            in_order and flat,
        )


def bench_trickle(seconds: float) -> list[Row]:
    """How a paced board's bytes reach a client reading as soon as they come."""
    proc, [url] = start_board("--pty")
    fd = open_raw(url)
    sizes: list[int] = []
    spans: list[float] = []
    try:
        end = time.monotonic() + seconds
        while time.monotonic() < end:
            os.write(fd, b"{Q:P}")  # a C record: 31 bytes, 32 ms of wire
            first = None
            seen = b""  # what came since the "{C" (or the last byte before one)
            until = time.monotonic() + 0.3
            while time.monotonic() < until:
                ready, _, _ = select.select([fd], [], [], 0.05)
                if ready:
                    chunk = os.read(fd, 4096)
                    sizes.append(len(chunk))
                    seen = seen[-1:] + chunk if first is None else seen + chunk
                    if first is None and b"{C" in seen:  # its start, split or not
                        first = time.monotonic()
                        seen = seen[seen.index(b"{C") :]
                    if first is not None and b"}$" in seen:  # its end, split or not
                        spans.append(time.monotonic() - first)
                        first, seen = None, b""
    finally:
        os.close(fd)
        stop(proc)
    read_p99 = percentile([float(x) for x in sizes], 99)
    span = statistics.median(spans) * 1000
    return [
        Row(
            "paced output: reads as the bytes come (9600 bps)",
            f"median read {statistics.median(sizes):.0f} bytes, p99 {read_p99:.0f}; a C "
            f"record arrives over {span:.1f} ms (median)",
            "runs of about 4 ms (p99 <= 5 bytes), C over 32 ms (±4)",
            read_p99 <= 5 and abs(span - 32) <= 4,
        )
    ]
