"""Every benchmark in one run, printed as one table (python -m bench.run_all).

Decoder throughput, CPU cost of `appmode board` and `appmode drive`, boards one process
serves, board-model steps, console key-to-byte latency, 60 s floods, paced throughput,
{Q:P} round trip, replay timing, start-up, the control port, the web page in Chromium and
a car shared over Zenoh across network namespaces, the car as a ROS 2 node.
`--quick` shortens the long ones.
"""

from __future__ import annotations

import argparse
import os
import platform
import statistics
import sys
import time
from collections.abc import Callable

from appmode.transcript.reading import read_transcript
from appmode.transcript.runner import SUITE, collect, run_virtual
from bench import (
    ble_link,
    conform_timing,
    control_port,
    decode_command,
    decoder,
    link_pacing,
    link_roundtrip,
    minibalance,
    network,
    page,
    replay_timing,
    ros,
    startup,
    viewers,
)
from bench.board_load import (
    bench_board_cpu,
    bench_drive_cpu,
    bench_flood,
    bench_key_latency,
    bench_many_boards,
    bench_model_steps,
    bench_trickle,
)
from bench.common import (
    Row,
    board,
    build,
    percentile,
)

DRIFT = 0.05
"""Drift of a replay's lateness (ms a minute) that still counts as none."""


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
    medians = startup.medians_ms(runs)
    base = medians["miniterm --help"]
    return [
        Row(
            f"start-up: {name}",
            f"{ms:.1f} ms, {ms / base:.2f}x miniterm --help ({base:.1f} ms)",
            f"<= {target:.1f}x miniterm",
            ms <= target * base,
        )
        for name, target in startup.TARGETS.items()
        for ms in [medians[name]]
    ]


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
                    f"drift {s['drift']:+.4f} ms/min (trend {s['trend']:+.3f})",
                    f"p99 <= MessageSync's, drift < {DRIFT} ms/min" if ours else "",
                    s["p99"] <= theirs["p99"] and abs(s["drift"]) < DRIFT if ours else None,
                )
            )
    return rows


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
        ("uart2", lambda: control_port.rows(quick)),
        ("web", lambda: page.rows(quick)),
        ("bluetooth", lambda: ble_link.rows(quick)),
        ("network", lambda: network.bench_network(quick)),
        ("ros", lambda: ros.rows(quick)),
        ("viewers", lambda: viewers.rows(quick)),
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
