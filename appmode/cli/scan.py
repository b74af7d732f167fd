"""`appmode scan`: the nearby cars' Bluetooth modules, each with the URL that drives it."""

from __future__ import annotations

import argparse
import json
import sys

from appmode.cli.commands import COMMANDS
from appmode.cli.options import Subparsers, number_type
from appmode.errors import AppmodeError
from appmode.text import escaped


def register(sub: Subparsers) -> argparse.ArgumentParser:
    scan = sub.add_parser(
        "scan",
        help=COMMANDS["scan"],
        description="Listen for BLE modules (HM-10, HC-08, JDY-08, … : a UART service "
        "FFE0 or Nordic UART) and list the paired classic modules (HC-05, HC-06), each "
        "with its signal and the URL to give drive, web or params; --probe says which "
        "firmware answers on each. Needs the bluetooth extra.",
    )
    scan.add_argument(
        "--time",
        type=number_type(0.5, 120),
        default=5.0,
        metavar="S",
        help="seconds to listen (default 5)",
    )
    scan.add_argument(
        "--all", action="store_true", help="list every device heard, not only cars' modules"
    )
    scan.add_argument(
        "--probe",
        action="store_true",
        help="connect to each module listed, listen, and read the parameters ({Q:P}) of "
        "one that streams records, as doctor does: say which firmware answered",
    )
    scan.add_argument("--json", action="store_true", help="one JSON object a line")
    return scan


def run(args: argparse.Namespace) -> int:
    import asyncio

    from appmode.bluetooth.availability import NO_BLEAK, explain

    try:
        from appmode.bluetooth.links.scan import Found, scan
    except ImportError:
        raise AppmodeError(NO_BLEAK) from None
    shown = sys.stderr.isatty()

    def progress(elapsed: float, count: int) -> None:
        if shown:
            sys.stderr.write(f"\rscanning {elapsed:3.0f}/{args.time:g} s: {count} heard ")
            sys.stderr.flush()

    try:
        found: list[Found] = asyncio.run(scan(args.time, progress))
    except ImportError:
        raise AppmodeError(NO_BLEAK) from None
    except Exception as exc:
        raise AppmodeError(explain(exc) or f"scanning failed: {exc}") from None
    finally:
        if shown:
            sys.stderr.write("\r\033[K")
    listed = [f for f in found if args.all or f.likely]
    firmware = _probe([f.url for f in listed], shown) if args.probe else {}
    if args.json:
        for one in listed:
            extra = {"firmware": firmware.get(one.url)} if args.probe else {}
            print(json.dumps(one.as_json() | extra))
        return 0
    if not listed:
        hidden = len(found) - len(listed)
        more = f" ({hidden} other devices: --all lists them)" if hidden else ""
        print(
            f"no car's module heard in {args.time:g} s{more}: switch the car on, bring "
            "it near, and disconnect any phone using it; a classic module (HC-05) "
            "shows once paired (bluetoothctl: pair ADDRESS)"
        )
        return 1
    head = ("kind", "name", "address", "signal", "service", "url")
    rows = [head + (("firmware",) if args.probe else ())] + [
        tuple(
            escaped(cell)  # a name is what a stranger's device says it is
            for cell in (
                f.kind,
                f.name or "?",
                f.address,
                f"{f.rssi} dBm" if f.rssi is not None else "paired",
                f.service or "-",
                f.url,
            )
            + ((firmware.get(f.url) or "-",) if args.probe else ())
        )
        for f in listed
    ]
    widths = [max(len(row[i]) for row in rows) for i in range(len(rows[0]))]
    for row in rows:
        print("  ".join(cell.ljust(w) for cell, w in zip(row, widths, strict=True)).rstrip())
    return 0


def _probe(urls: list[str], shown: bool) -> dict[str, str | None]:
    """What answers at each URL, one after the other (a module takes one central): the
    firmware's profile for a car, else None. {Q:P} goes only to a port that streams
    records (host.probe)."""
    import threading

    from appmode.host.probe import probe
    from appmode.ports.target import parse_target

    stop = threading.Event()
    answers: dict[str, str | None] = {}
    for url in urls:

        def say(text: str, url: str = url) -> None:
            if shown:
                sys.stderr.write(f"\r\033[Kprobing {escaped(url)}: {escaped(text)}")
                sys.stderr.flush()

        finding = probe(parse_target(url), stop, say)
        answers[url] = (finding.profile or "unknown") if finding.is_car else None
    if shown:
        sys.stderr.write("\r\033[K")
    return answers
