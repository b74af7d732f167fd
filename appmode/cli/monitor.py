"""`appmode monitor`: print decoded records as they arrive."""

from __future__ import annotations

import argparse
import sys
from contextlib import ExitStack
from typing import TextIO

from appmode.cli.hostio import open_host, show
from appmode.cli.options import DAY, Subparsers, add_record, add_url, number_type
from appmode.protocol import app


def register(sub: Subparsers) -> argparse.ArgumentParser:
    mon = sub.add_parser(
        "monitor",
        help="print decoded records as they arrive",
        description="Print each record as it arrives (and each undecodable run of bytes), "
        "until Ctrl-C. Link losses are reported on stderr and the link is reopened. A "
        "monitor only listens: it writes nothing to the port unless --stop-on-exit.",
    )
    add_url(mon)
    mon.add_argument("--json", action="store_true", help="print JSON Lines")
    mon.add_argument(
        "--duration",
        type=number_type(0, DAY, low_open=True),
        metavar="SECONDS",
        help="stop after this long",
    )
    mon.add_argument(
        "--count",
        type=number_type(1, 1e9, whole=True),
        metavar="N",
        help="stop after N records (A, B or C; undecodable bytes do not count)",
    )
    mon.add_argument(
        "--stop-on-exit",
        action="store_true",
        help="send Z when the monitor ends (it sends nothing otherwise)",
    )
    add_record(mon)
    return mon


def run(args: argparse.Namespace) -> int:
    return run_monitor(
        args.url,
        as_json=args.json,
        duration=args.duration,
        count=args.count,
        record=args.record,
        stop_on_exit=args.stop_on_exit,
        out=sys.stdout,
    )


def run_monitor(
    url: str,
    *,
    as_json: bool,
    duration: float | None,
    count: int | None,
    record: str | None,
    out: TextIO,
    stop_on_exit: bool = False,
) -> int:
    """Print records as they arrive, until interrupted, `duration` or `count` records."""
    seen = 0
    with ExitStack() as stack:
        host = open_host(stack, url, record, stop_on_close=stop_on_exit)
        print(f"monitoring {url} (Ctrl-C to stop)", file=sys.stderr, flush=True)
        try:
            for event in host.events(duration):
                show(host, event, out, as_json)
                seen += isinstance(event, app.RECORDS)
                if count is not None and seen >= count:
                    break
        finally:
            stats = host.state.stats
            print(
                f"monitor: {stats.records} records, {stats.errors} errors, "
                f"{stats.bytes_in} bytes in {host.now():.1f} s",
                file=sys.stderr,
            )
    return 0
