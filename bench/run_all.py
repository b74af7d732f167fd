"""Every benchmark in one run, printed as one table (python bench/run_all.py).

Decoder throughput, CPU cost of `appmode board` and `appmode drive`, boards one process
serves, board-model steps, console key-to-byte latency, 60 s floods, paced throughput,
{Q:P} round trip, replay timing, start-up, the control port and the web page in Chromium.
`--quick` shortens the long ones.
"""

from __future__ import annotations

import argparse
import contextlib
import io
import os
import platform
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

import bluetooth
import conform_timing
import decode_command
import decoder
import link_pacing
import link_roundtrip
import many_boards
import minibalance
import replay_timing
import serial
import startup
import uart2
import web
from common import (
    Row,
    board,
    build,
    cpu_seconds,
    floor_row,
    over_floor,
    over_floor_met,
    percentile,
    share_and_floor,
)

from appmode.board.firmware import TICK, Board
from appmode.transcript.reading import read_transcript
from appmode.transcript.runner import SUITE, collect, run_virtual

TICKS = os.sysconf("SC_CLK_TCK")


FLAT_MIB = 4.0
"""Growth of a flooded board's memory (RSS) that still counts as flat."""
DRIFT = 0.05
"""Drift of a replay's lateness (ms a minute) that still counts as none."""


def rss_mib(pid: int) -> float:
    for line in Path(f"/proc/{pid}/status").read_text().splitlines():
        if line.startswith("VmRSS:"):
            return int(line.split()[1]) / 1024
    return 0.0


def start_board(*args: str) -> tuple[subprocess.Popen[str], list[str]]:
    proc = subprocess.Popen(
        [sys.executable, "-m", "appmode", "board", "--quiet", *args],
        stdout=subprocess.PIPE,
        text=True,
    )
    assert proc.stdout is not None
    count = int(args[args.index("--count") + 1]) if "--count" in args else 1
    urls: list[str] = []
    while len(urls) < count:  # each board prints `port: …`, then `uart2: …`
        line = proc.stdout.readline()
        if not line:
            stop(proc)
            raise RuntimeError(f"appmode board {' '.join(args)} ended before its ports")
        if line.startswith("port: "):
            urls.append(line.removeprefix("port: ").strip())
    return proc, urls


def stop(proc: subprocess.Popen[str]) -> None:
    proc.terminate()
    proc.wait(10)


def open_raw(path: str) -> int:
    fd = os.open(path, os.O_RDWR | os.O_NOCTTY | os.O_NONBLOCK)
    tty.setraw(fd)
    return fd


# ---------------------------------------------------------------- measurements


def bench_decoder(quick: bool) -> list[Row]:
    r = decoder.compare(2.0 if quick else 10.0, 0.01, 4096)
    four, thirty_two = decoder.one_call()
    return [
        Row(
            "decoder, 1 % noise, 4 KiB chunks",
            f"{r['ours_mbs']:.2f} MB/s, {r['ours_rps']:,.0f} records/s",
            ">= 8 MB/s",
            r["ours_mbs"] >= 8,
        ),
        Row(
            "byte-at-a-time decoder (firmware way)",
            f"{r['naive_mbs']:.2f} MB/s, "
            f"{r['naive_rps']:,.0f} records/s; appmode {r['speedup']:.1f}x",
            ">= 2x",
            r["speedup"] >= 2,
        ),
        *(
            Row(
                f"garbage: {name}",
                f"{rate:.2f} MB/s",
                "linear (MB/s of the order of clean: >= 1/4 of it)",
                rate >= r["ours_mbs"] / 4,
            )
            for name, rate in decoder.garbage(0.5 if quick else decoder.GARBAGE_MB).items()
        ),
        *(
            Row(
                f"{name} against its byte loop, {len(ratios)} inputs",
                f"slowest {min(ratios)[0]:.2f}x ({min(ratios)[1]}), "
                f"median {statistics.median(x for x, _ in ratios):.2f}x",
                ">= 1x on every input",
                min(ratios)[0] >= 1,
            )
            for name, rows in decoder.against_byte_loops(0.3 if quick else 1.0).items()
            for ratios in [[(x, what) for what, x in rows]]
        ),
        Row(
            "one BoardDecoder.feed() of 4 MB, of 32 MB",
            f"{four:.2f} MB/s, {thirty_two:.2f} MB/s",
            "linear: the same MB/s (within 25 %)",
            thirty_two >= 0.75 * four,
        ),
    ]


def bench_decode_command(quick: bool) -> list[Row]:
    r = decode_command.compare(2.0 if quick else 10.0)
    return [
        Row(
            f"appmode decode FILE, {r['mb']:.0f} MB, 1 % noise",
            f"{r['mb'] / r['ours']:.2f} MB/s; a byte loop writing the same "
            f"{r['out_mb']:.0f} MB {r['mb'] / r['loop']:.2f} MB/s; appmode {r['speedup']:.2f}x",
            ">= 1.5x the loop",
            r["speedup"] >= 1.5,
        )
    ]


def bench_startup(runs: int) -> list[Row]:
    base = startup.median_ms(startup.COMMANDS["miniterm --help"], runs)
    return [
        Row(
            f"start-up: {name}",
            f"{ms:.1f} ms, {ms / base:.1f}x miniterm --help ({base:.1f} ms)",
            "<= 1.5x miniterm",
            ms <= 1.5 * base,
        )
        for name, command in startup.COMMANDS.items()
        if not name.startswith("miniterm")
        for ms in [startup.median_ms(command, runs)]
    ]


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

    def send(data: bytes) -> None:
        if data in (b"A", b"Z"):
            sent.append(time.perf_counter())
        real_send(data)

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


def bench_links(quick: bool) -> list[Row]:
    rate, error = link_pacing.measure(5.0 if quick else 10.0)
    rows = [
        Row(
            "paced throughput over a pty",
            f"{rate:.2f} bytes/s (±{error:.2f}) = {rate / 9.6:.3f} % of 960 (slope of bytes "
            "over time)",
            ">= 99.5 %, <= 100 % (within its standard error)",
            rate >= 0.995 * 960 and rate - error <= 960,
        )
    ]
    for label, option in (("pty", ("--pty",)), ("TCP", ("--listen", "0"))):
        with board(*option, "--no-pace") as url:
            extra = [x * 1000 for x in link_roundtrip.measure(url, 50 if quick else 200)]
        p99 = percentile(extra, 99)
        rows.append(
            Row(
                f"{{Q:P}} -> C over {label}, beyond the next slot",
                f"median {statistics.median(extra):.2f} ms, p99 {p99:.2f} ms",
                "p99 < 2 ms",
                p99 < 2,
            )
        )
    return rows


def bench_replay(events: int) -> list[Row]:
    rows: list[Row] = []
    for kind in ("idle", "busy", "pytest"):
        result = replay_timing.measure(events, 0.01, kind)
        if result is None:
            return [Row(f"replay, {events} events at 10 ms", "python-can not installed", "", False)]
        theirs = result["python-can MessageSync"]
        for name, s in result.items():
            ours = name == "appmode play"
            rows.append(
                Row(
                    f"{name}, {events} events at 10 ms, {kind}",
                    f"median {s['median']:.3f} ms, p99 {s['p99']:.3f} ms, "
                    f"drift {s['drift']:+.4f} ms/min",
                    f"p99 <= MessageSync's, drift < {DRIFT} ms/min" if ours else "",
                    s["p99"] <= theirs["p99"] and abs(s["drift"]) < DRIFT if ours else None,
                )
            )
    return rows


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


def bench_conform_timing(sends: int) -> list[Row]:
    late = [x * 1000 for x in conform_timing.measure(sends)]
    p99 = percentile(late, 99)
    return [
        Row(
            f"conform --board: {sends} sends, lateness at the board",
            f"median {statistics.median(late):.2f} ms, p99 {p99:.2f} ms",
            "p99 < 2 ms",
            p99 < 2,
        )
    ]


def bench_conform_virtual(runs: int) -> list[Row]:
    """`appmode conform` with no board: the shipped suite on virtual time, in process."""
    transcripts = [read_transcript(path) for path in collect([str(SUITE)])]
    walls, passed = [], True
    for _ in range(runs):
        started = time.perf_counter()
        results = [run_virtual(transcript) for transcript in transcripts]
        walls.append(time.perf_counter() - started)
        passed = passed and all(result.passed for result in results)
    virtual = sum(result.seconds for result in results)
    best = min(walls)
    return [
        Row(
            f"conform on virtual time: the suite ({len(transcripts)} transcripts)",
            f"{virtual:.0f} s of board time in {best:.2f} s (best of {runs}), "
            f"median {statistics.median(walls):.2f} s" + ("" if passed else "; FAILURES"),
            "< 1 s, every transcript passing",
            best < 1 and passed,
        )
    ]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--quick", action="store_true", help="shorter runs (about 2 min)")
    parser.add_argument(
        "--only", action="append", metavar="NAME", help="run only this part (repeatable)"
    )
    parser.add_argument(
        "--busy", action="store_true", help="run beside a second process that keeps a core busy"
    )
    args = parser.parse_args()
    quick = args.quick
    plan: list[tuple[str, Callable[[], list[Row]]]] = [
        ("decoder", lambda: bench_decoder(quick)),
        ("board model", bench_model_steps),
        ("key latency", lambda: bench_key_latency(100 if quick else 300)),
        ("decode command", lambda: bench_decode_command(quick)),
        ("start-up", lambda: bench_startup(5 if quick else 15)),
        ("board CPU", lambda: bench_board_cpu(12 if quick else 120)),
        ("drive CPU", lambda: bench_drive_cpu(10 if quick else 30)),
        ("boards per core", lambda: bench_many_boards([200, 500, 1000], 5 if quick else 15)),
        ("trickle", lambda: bench_trickle(3 if quick else 10)),
        ("links", lambda: bench_links(quick)),
        (
            "floods",
            lambda: [
                bench_flood(10 if quick else 60, paced, garbage)
                for paced, garbage in ((False, False), (True, False), (False, True))
            ],
        ),
        ("replay", lambda: bench_replay(1000 if quick else 10_000)),
        ("conform virtual", lambda: bench_conform_virtual(3 if quick else 10)),
        ("conform timing", lambda: bench_conform_timing(200 if quick else 600)),
        ("minibalance", lambda: minibalance.rows(30 if quick else 100)),
        ("uart2", lambda: uart2.rows(quick)),
        ("web", lambda: web.rows(quick)),
        ("bluetooth", lambda: bluetooth.rows(quick)),
    ]
    if args.only:
        unknown = set(args.only) - {name for name, _ in plan}
        if unknown:
            parser.error(f"no part {', '.join(sorted(unknown))}; parts: {[n for n, _ in plan]}")
        plan = [(name, run) for name, run in plan if name in args.only]
    rows: list[Row] = []
    failed: list[str] = []
    with replay_timing.load("busy1" if args.busy else "idle"):
        for name, run in plan:
            print(f"running: {name} …", file=sys.stderr, flush=True)
            try:
                rows += run()
            except (Exception, SystemExit) as error:  # the other parts' rows are kept
                print(f"{name}: failed: {error}", file=sys.stderr, flush=True)
                rows.append(Row(name, f"failed: {error}", "", False))
                failed.append(name)
    machine = (
        f"{platform.machine()}, {os.cpu_count()} cores, Python "
        f"{platform.python_version()}, {platform.system()} {platform.release()}"
    )
    beside = "beside a busy process" if args.busy else "idle"
    print(
        f"appmode benchmarks — {time.strftime('%Y-%m-%d')} — {machine} — {beside} — "
        f"appmode {build()}"
    )
    width = max(len(r.benchmark) for r in rows)
    print(f"| {'benchmark'.ljust(width)} | result | target | |")
    print(f"|{'-' * (width + 2)}|---|---|---|")
    for row in rows:
        mark = {True: "met", False: "**missed**", None: ""}[row.met]
        print(f"| {row.benchmark.ljust(width)} | {row.result} | {row.target} | {mark} |")
    missed = [row.benchmark for row in rows if row.met is False]
    print(f"{len(missed)} missed of {sum(row.met is not None for row in rows)} with a target")
    if failed:
        raise SystemExit(f"run_all: failed: {', '.join(failed)} (the table has the rest)")


if __name__ == "__main__":
    main()
