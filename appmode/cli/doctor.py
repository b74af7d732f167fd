"""`appmode doctor`: find the car, port by port, and say how to drive it or what to fix."""

from __future__ import annotations

import argparse
import json
import shutil
import sys
import threading
import time
from typing import TYPE_CHECKING

from appmode.cli.commands import COMMANDS
from appmode.cli.options import Subparsers
from appmode.text import counted, wrapped

if TYPE_CHECKING:  # imported by `run`: `appmode --help` does not load the host
    from concurrent.futures import Future

    from appmode.host import probe

WORKERS = 8
"""Ports listened to at once."""
REFRESH = 0.1
"""Seconds between redraws of the progress line."""
BLUETOOTH_SCAN = 3.0
"""Seconds `doctor` listens for BLE modules."""


def register(sub: Subparsers) -> argparse.ArgumentParser:
    doctor = sub.add_parser(
        "doctor",
        help=COMMANDS["doctor"],
        description="Check serial ports for a car: open each (saying how to fix a "
        "permission, a busy port or an unbound Bluetooth port), listen at 9600 bps for "
        "APP records and at 115200 for the control port (UART2), try the other common "
        "rates when the bytes are not records, read the parameters with {Q:P} (the only "
        "bytes it sends, and only to a port that streams records: never a drive letter), "
        "and tell the firmware from its record period. With no URL it also checks the "
        "Bluetooth modules it hears (ble://) or finds paired (bt://). Ends with one "
        "verdict per port. "
        "Exit status: 0 when a car's port was found, 1 when none.",
    )
    doctor.add_argument(
        "urls",
        nargs="*",
        metavar="URL",
        help="the ports to check (default: every serial port, as appmode ports lists them, "
        "and the Bluetooth modules appmode scan finds)",
    )
    doctor.add_argument(
        "--no-bluetooth",
        action="store_true",
        help="with no URL: do not look for Bluetooth modules (a 3-second scan)",
    )
    doctor.add_argument("--json", action="store_true", help="print one JSON object per port")
    return doctor


def run(args: argparse.Namespace) -> int:
    urls: list[str] = list(dict.fromkeys(args.urls))
    if not urls:
        from appmode.ports.listing import serial_ports

        urls = [port.device for port in serial_ports()]
        if not args.no_bluetooth:
            urls += _bluetooth()
    if not urls:
        print(
            wrapped(
                "no serial ports found: plug in the USB-UART adapter, or pair the car's "
                "Bluetooth module (appmode scan lists what is near); 'appmode board --pty' "
                "serves a simulated board to try this on",
                indent="",
            ),
            file=sys.stderr,
        )
        return 1
    findings = _check(urls)
    for finding in findings:
        if args.json:
            sys.stdout.write(json.dumps(finding.to_json()) + "\n")
        else:
            sys.stdout.write(_text(finding) + "\n")
    return 0 if any(f.is_car for f in findings) else 1


def _bluetooth() -> list[str]:
    """The URLs of the cars' Bluetooth modules near or paired; where none can be looked
    for, a line on stderr says why."""
    import asyncio

    try:
        from appmode.bluetooth.availability import explain
        from appmode.bluetooth.scan import scan
    except ImportError:
        print("doctor: Bluetooth not looked for: pip install 'appmode[bluetooth]'", file=sys.stderr)
        return []
    if sys.stderr.isatty():
        sys.stderr.write("doctor: listening for Bluetooth modules …")
        sys.stderr.flush()
    try:
        found = asyncio.run(scan(BLUETOOTH_SCAN, lambda *_: None))
    except Exception as exc:  # no Bluetooth here: said, and the serial ports are checked
        print(f"doctor: Bluetooth not looked for: {explain(exc) or exc}", file=sys.stderr)
        return []
    finally:
        if sys.stderr.isatty():
            sys.stderr.write("\r\x1b[K")
    return [f.url for f in found if f.likely]


def _text(finding: probe.Finding) -> str:
    mark = "ok" if finding.is_car else "--"
    return "\n".join(
        (
            wrapped(f"{mark} {finding.url}: {finding.verdict}", indent="   "),
            wrapped(f"   {finding.fix}", indent="   "),
        )
    )


def _check(urls: list[str]) -> list[probe.Finding]:
    """Probe every port at once, showing progress on a terminal."""
    from concurrent.futures import ThreadPoolExecutor

    from appmode.host import probe

    stop = threading.Event()
    doing = dict.fromkeys(urls, "waiting")

    def mark(url: str) -> probe.Progress:
        def say(text: str) -> None:
            doing[url] = text

        return say

    pool = ThreadPoolExecutor(max_workers=min(WORKERS, len(urls)))
    futures: dict[str, Future[probe.Finding]] = {
        url: pool.submit(probe.probe, url, stop, mark(url)) for url in urls
    }
    show = sys.stderr.isatty()
    try:
        while not all(f.done() for f in futures.values()):
            if show:
                _progress(futures, doing)
            time.sleep(REFRESH)
    finally:
        stop.set()
        pool.shutdown(wait=True)
        if show:
            sys.stderr.write("\r\x1b[K")
            sys.stderr.flush()
    return [futures[url].result() for url in urls]


def _progress(futures: dict[str, Future[probe.Finding]], doing: dict[str, str]) -> None:
    done = sum(f.done() for f in futures.values())
    busy = next((url for url, f in futures.items() if not f.done()), "")
    line = f"doctor: {done} of {counted(len(futures), 'port')} checked · {busy}: {doing[busy]}"
    width = shutil.get_terminal_size().columns - 1
    sys.stderr.write("\r\x1b[K" + line[:width])
    sys.stderr.flush()
