"""`appmode monitor`: print decoded records as they arrive."""

from __future__ import annotations

import argparse
import sys
from contextlib import ExitStack
from typing import TextIO

from appmode.cli.hostio import open_host, show
from appmode.cli.options import DAY, Subparsers, add_record, add_url, number_type
from appmode.host.state import LinkStatus


def register(sub: Subparsers) -> argparse.ArgumentParser:
    mon = sub.add_parser(
        "monitor",
        help="print decoded records as they arrive",
        description="Print each record as it arrives (and each undecodable run of bytes), "
        "until Ctrl-C. Link losses are reported on stderr and the link is reopened.",
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
        "--count", type=number_type(1, 1e9, whole=True), metavar="N", help="stop after N records"
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
) -> int:
    """Print records as they arrive, until interrupted, `duration` or `count` records."""
    seen = 0
    with ExitStack() as stack:
        host = open_host(stack, url, record)
        print(f"monitoring {url} (Ctrl-C to stop)", file=sys.stderr, flush=True)
        try:
            for event in host.events(duration):
                show(host, event, out, as_json)
                seen += not isinstance(event, LinkStatus)
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
