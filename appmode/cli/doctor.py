"""`appmode doctor`: find the car, port by port, and say how to drive it or what to fix."""

from __future__ import annotations

import argparse
import json
import shlex
import shutil
import sys
import threading
import time
from dataclasses import replace
from typing import TYPE_CHECKING

from appmode.cli.commands import COMMANDS
from appmode.cli.options import Subparsers, add_chassis, target
from appmode.errors import install_line
from appmode.text import counted, escaped, wrapped

if TYPE_CHECKING:  # imported by `run`: `appmode --help` does not load the host
    from concurrent.futures import Future

    from appmode.host import identify, probe
    from appmode.host.heard import Heard
    from appmode.ports.target import Target

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
        type=target,
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
    add_chassis(doctor, "listen for a chassis port only, at 115200 bps (quicker)")
    return doctor


def run(args: argparse.Namespace) -> int:
    from appmode.ports.target import parse_target

    _namesake()
    urls = {t.url: t for t in args.urls}
    if not urls:
        from appmode.ports.listing import serial_ports

        found = [port.device for port in serial_ports()]
        if not args.no_bluetooth:
            found += _bluetooth()
        urls = {url: parse_target(url) for url in found}
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
    from appmode.line.wire import CHASSIS_BAUD

    findings = _check(list(urls.values()), (CHASSIS_BAUD,) if args.chassis else None)
    if args.chassis:  # what else a port is, at a rate tried for a chassis, is not said
        heard = ("app", "uart2", "silent", "text", "noise")  # a probe's finding, not a failure
        findings = [replace(f, kind="no chassis") if f.kind in heard else f for f in findings]
    for finding in findings:
        if args.json:
            sys.stdout.write(json.dumps(to_json(finding)) + "\n")
        else:
            sys.stdout.write(_text(finding) + "\n")
    return 0 if any(f.is_car for f in findings) else 1


def _namesake() -> None:
    """Say so when PyPI's other `appmode` (a Jupyter extension) is installed here too."""
    from importlib import metadata

    try:
        metadata.distribution("appmode")
    except metadata.PackageNotFoundError:
        return
    print(
        wrapped(
            "doctor: the Jupyter extension also named appmode is installed in this "
            "environment: both install a package named appmode, and the one installed last "
            "overwrote the other's files. pip uninstall appmode, then install appmode-car "
            "again, or keep each in a virtual environment of its own",
            indent="",
        ),
        file=sys.stderr,
    )


def _bluetooth() -> list[str]:
    """The URLs of the cars' Bluetooth modules near or paired; where none can be looked
    for, a line on stderr says why."""
    import asyncio

    try:
        from appmode.bluetooth.availability import explain
        from appmode.bluetooth.links.scan import scan
    except ImportError:
        print(f"doctor: Bluetooth not looked for: {install_line('bluetooth')}", file=sys.stderr)
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
            wrapped(f"{mark} {escaped(finding.url)}: {verdict(finding)}", indent="   "),
            wrapped(f"   {fix(finding)}", indent="   "),
        )
    )


def verdict(finding: probe.Finding) -> str:
    """What the port is, in a line."""
    rate = "" if finding.fixed or finding.baud is None else f" at {finding.baud} bps"
    shown = finding.shown
    if finding.kind == "app":
        return _car_verdict(finding, rate)
    if finding.kind == "uart2":
        what = (
            "encoder reports"
            if shown and shown.reports
            else "the reference firmware's status bursts (§13.1)"
        )
        return f"this is a car's control port (UART2){rate}: it sends {what}"
    if finding.kind == "no chassis":
        return "no chassis port: no status frames at 115200 bps"
    if finding.kind == "chassis":
        booting = (
            " (Flag_Stop set: booting, or stopped by the board)" if shown and shown.booting else ""
        )
        return f"this is a WHEELTEC chassis port{rate}: status frames every 50 ms{booting}"
    if finding.kind == "silent":
        spent = sum(h.seconds for h in finding.heard)
        return f"silent: nothing came in {spent:.1f} s{_tried(finding)}"
    if finding.kind == "text":
        sample = bytes(shown.sample if shown else b"").decode("ascii", "replace").split()
        return f"not a board: it sends text{rate} ({' '.join(sample)[:40]!r}…), no records"
    if finding.kind == "noise":
        return f"bytes but no records{_tried(finding)}"
    if finding.kind == "unopened":
        return f"cannot be opened: {finding.failure.partition(': ')[0]}"
    return f"it opened, then failed while listening ({finding.failure})"


def _car_verdict(finding: probe.Finding, rate: str) -> str:
    period = f"a record every {5 * round((finding.period_ms or 0) / 5)} ms"  # a rhythm
    what = f"{finding.profile or 'unknown'} firmware ({period})"
    if finding.values is None:
        return f"a car's APP port{rate}, {what}; its parameters did not come"
    from appmode.protocol import param_values

    pairs = zip(finding.specs, finding.values, strict=False)
    shown = ", ".join(f"{s.name}={param_values.to_user(s, v)}" for s, v in pairs)
    off = finding.baud not in (None, 9600) and not finding.fixed
    note = f" (its Bluetooth module or UART runs at {finding.baud}, not 9600)" if off else ""
    return f"this is a car: APP port{rate}{note}, {what}, parameters {shown}"


def _tried(finding: probe.Finding) -> str:
    tried = " or ".join(f"{h.baud}" for h in finding.heard)
    return "" if finding.fixed else f" at {tried} bps"


def fix(finding: probe.Finding) -> str:
    """What to do next: the command that drives the car, or what to fix."""
    url = shlex.quote(finding.url)
    if finding.kind == "app":
        drive = _drive_it(finding)
        return f"{finding.failure}; {drive}" if finding.values is None else drive
    if finding.kind == "uart2":
        return (
            f"drive it with: appmode drive {_at_rate(finding, 115200)} --uart2 (it takes "
            "the motion over from the APP port)"
        )
    if finding.kind == "no chassis":
        return f"appmode doctor {url} (without --chassis) finds what it is"
    if finding.kind == "chassis":
        where = _at_rate(finding, 115200)
        if finding.profile is not None or finding.target.simulated:  # sim:// names its own
            return f"drive it with: appmode drive {where} --chassis (it moves sideways: mecanum)"
        return (
            f"drive it with: appmode drive {where} --chassis --profile wheeltec-mec, "
            "wheeltec-akm or wheeltec-diff: your car's kind (its status frames do not say)"
        )
    if finding.kind == "silent":
        return (
            "check that the car is on and wired TX to RX (or paired, for Bluetooth); a "
            "control port (UART2) with its encoder report off is silent until spoken to: "
            f"appmode params {url} --uart2 reads it (and takes the motion over)"
        )
    if finding.kind == "text":
        return (
            "name the car's port instead (appmode ports lists them); a pty path may now "
            "be another program's: restart the board, or use board --link"
        )
    if finding.kind == "noise":
        return (
            "not a board, or at a rate appmode does not try: check the wiring (TX to RX, a "
            "common ground) and the module's rate"
        )
    if finding.kind == "unopened":
        what, _, then = finding.failure.partition(": ")
        return then or what
    return (
        "the device went away: check the cable or adapter (or the program that served "
        "this pty), then run appmode doctor again"
    )


def _at_rate(finding: probe.Finding, usual: int) -> str:
    """The port's URL at the rate it showed (`?baud=` when not the port's usual one)."""
    bare = finding.target.url if finding.fixed else finding.target.path
    rate = finding.baud
    return shlex.quote(bare if finding.fixed or rate in (None, usual) else f"{bare}?baud={rate}")


def _drive_it(finding: probe.Finding) -> str:
    """The command that drives a car, or how to write a profile for a firmware that fits
    none."""
    # a shared car's URL shows its key as …: the one given, which holds it, drives it
    where = "URL" if finding.target.remote is not None else _at_rate(finding, 9600)
    nearest: identify.Judgement | None = finding.nearest
    if finding.profile is None and nearest is not None:
        name = nearest.profile.name
        return (
            f"its records fit no shipped profile (nearest: {name}, but "
            f"{'; '.join(nearest.against[:2])}): write one for it, starting from "
            f"appmode profile show {name} --toml > mycar.toml, then "
            f"appmode drive {where} --profile mycar.toml"
        )
    flag = ""  # a sim:// URL names its own profile
    if finding.profile not in (None, "sheet") and not finding.target.simulated:
        flag = f" --profile {finding.profile}"
    given = " (the zenoh:// URL given, its key included)" if where == "URL" else ""
    return f"drive it with: appmode drive {where}{flag}{given}"


def to_json(finding: probe.Finding) -> dict[str, object]:
    """A finding as `doctor --json` prints it."""
    from appmode.protocol import param_values

    values = finding.values
    return {
        "port": finding.url,
        "kind": finding.kind,
        "car": finding.is_car,
        "verdict": verdict(finding),
        "fix": fix(finding),
        "baud": finding.baud,
        "profile": finding.profile,
        "record_period_ms": None if finding.period_ms is None else round(finding.period_ms, 1),
        "params": None
        if values is None
        else {
            s.name: param_values.user_number(s, v)
            for s, v in zip(finding.specs, values, strict=False)
        },
        "heard": [_heard(h) for h in finding.heard],
    }


def _heard(heard: Heard) -> dict[str, object]:
    return {
        "baud": heard.baud,
        "seconds": round(heard.seconds, 2),
        "bytes": heard.size,
        "records": heard.records,
        "uart2_bursts": heard.uart2_bursts,
    }


def _check(targets: list[Target], rates: tuple[int, ...] | None) -> list[probe.Finding]:
    """Probe every port at once (at `rates` only, if given), showing progress on a
    terminal."""
    from concurrent.futures import ThreadPoolExecutor

    from appmode.host import probe

    stop = threading.Event()
    doing = {t.url: "waiting" for t in targets}

    def mark(url: str) -> probe.Progress:
        def say(text: str) -> None:
            doing[url] = text

        return say

    pool = ThreadPoolExecutor(max_workers=min(WORKERS, len(targets)))
    futures: dict[str, Future[probe.Finding]] = {
        t.url: pool.submit(probe.probe, t, stop, mark(t.url), rates) for t in targets
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
    return [futures[t.url].result() for t in targets]


def _progress(futures: dict[str, Future[probe.Finding]], doing: dict[str, str]) -> None:
    done = sum(f.done() for f in futures.values())
    busy = next((url for url, f in futures.items() if not f.done()), "")
    line = f"doctor: {done} of {counted(len(futures), 'port')} checked · {busy}: {doing[busy]}"
    width = shutil.get_terminal_size().columns - 1
    sys.stderr.write("\r\x1b[K" + line[:width])
    sys.stderr.flush()
