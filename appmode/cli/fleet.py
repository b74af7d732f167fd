"""`appmode fleet`: the cars a key opens on the network, live; `fleet stop` stops them."""

from __future__ import annotations

import argparse
import json
import sys
import time
from typing import TYPE_CHECKING, Any

from appmode.cli.commands import COMMANDS
from appmode.cli.options import Subparsers, add_host_id, endpoint
from appmode.text import escaped

if TYPE_CHECKING:
    from appmode.net.fleet import Car
    from appmode.net.signature import Trust

REFRESH = 1.0
"""Seconds between two looks at the fleet, live."""
COLUMNS = ("car", "profile", "battery", "in force", "driver", "latency", "machine")


def register(sub: Subparsers) -> argparse.ArgumentParser:
    fleet = sub.add_parser(
        "fleet",
        help=COMMANDS["fleet"],
        description="List the cars shared with appmode share that a key opens (on this "
        "LAN by scouting, or through --connect): name, firmware profile, battery, whether "
        "it was last told to move, who drives it, how long its host took to answer. Live "
        "on a terminal (Ctrl-C ends it), once with --json or into a pipe. 'fleet stop' "
        "stops every one of them and prints each car's confirmation.",
    )
    fleet.add_argument("action", nargs="?", choices=("stop",), help="stop every car")
    fleet.add_argument(
        "--connect",
        action="append",
        type=endpoint,
        default=[],
        metavar="ENDPOINT",
        help="a share or a router to ask through: tcp/HOST:PORT (default: scout this LAN)",
    )
    fleet.add_argument("--key", help="the cars' key (default: this machine's share key)")
    add_host_id(fleet)
    fleet.add_argument("--json", action="store_true", help="print the fleet once, as JSON")
    return fleet


def run(args: argparse.Namespace) -> int:
    from appmode.cli.share import a_clients_key
    from appmode.net.config import close_session, open_session, zenoh_module
    from appmode.net.signature import Trust

    zenoh_module()
    connect = tuple(args.connect)
    key = a_clients_key(args.key, "fleet")
    trust = Trust(key, args.host_id)
    session = open_session("client", key, connect=connect, scout=not connect)
    try:
        if args.action == "stop":
            return _stop(session, trust, args.json)
        if args.json or not sys.stdout.isatty():
            return _once(session, trust, args.json)
        return _live(session, trust)
    finally:
        close_session(session)


def _once(session: Any, trust: Trust, as_json: bool) -> int:
    from appmode.net.fleet import cars

    found = cars(session, trust)
    if as_json:
        rows = [{"name": c.name, **c.info, "latency_ms": round(c.latency_ms, 2)} for c in found]
        sys.stdout.write(json.dumps(rows) + "\n")
    else:
        sys.stdout.write(table(found) + "\n")
    if not found and trust.strangers:
        print(f"appmode: no car's host answered{trust.refusal()}", file=sys.stderr)
    return 0 if found else 1


def _live(session: Any, trust: Trust) -> int:
    from appmode.net.fleet import cars

    shown = 0
    try:
        while True:
            text = table(cars(session, trust, wait=REFRESH)) + "\n"
            sys.stdout.write(f"\x1b[{shown}A\x1b[J" if shown else "")
            sys.stdout.write(text)
            sys.stdout.flush()
            shown = text.count("\n")
            time.sleep(REFRESH / 2)
    except KeyboardInterrupt:
        return 0


def table(found: list[Car]) -> str:
    """The fleet, a car a row (what a car's host says is shown escaped)."""
    if not found:
        return "no car answers: is appmode share running, with this key, on this LAN?"
    rows = [COLUMNS, *(_row(car) for car in found)]
    widths = [max(len(row[i]) for row in rows) for i in range(len(COLUMNS))]
    return "\n".join(
        "  ".join(cell.ljust(w) for cell, w in zip(row, widths, strict=True)).rstrip()
        for row in rows
    )


def _row(car: Car) -> tuple[str, ...]:
    info = car.info
    driver = info.get("driver")
    battery = info.get("battery")
    return (
        escaped(car.name),
        _cell(info.get("profile", "?")),
        "—" if battery is None else _cell(f"{battery} %"),
        _cell(_motion(info)),
        _cell(driver.get("machine")) if isinstance(driver, dict) else "—",
        f"{car.latency_ms:.1f} ms",
        _cell(info.get("machine", "?")),
    )


CELL = 40
"""Characters of a cell at most: what a car's host says is data from outside."""


def _cell(value: object) -> str:
    """`value` as a cell: escaped, and cut to CELL characters."""
    text = escaped(str(value))
    return text if len(text) <= CELL else text[: CELL - 1] + "…"


def _motion(info: dict[str, Any]) -> str:
    """What the car does: what it was told, else what its records show."""
    if info.get("in_force"):
        return str(info["in_force"])
    if info.get("records_moving") is True:
        return "MOVING (its records)"
    return "stopped" if info.get("records_moving") is False else "stopped (not confirmed)"


def _stop(session: Any, trust: Trust, as_json: bool) -> int:
    from appmode.net.fleet import stop_all

    answers = stop_all(session, trust)
    if as_json:
        sys.stdout.write(json.dumps(answers) + "\n")
    for answer in [] if as_json else answers:
        name = escaped(str(answer.get("name")))
        if not answer.get("sent"):
            said = "its stop was NOT delivered: its link is down; it may still be moving"
        elif answer.get("confirmed") is None:
            said = "stop sent (it sends no telemetry to confirm it)"
        else:
            said = "stopped (confirmed)" if answer["confirmed"] else "stop sent, NOT confirmed"
        print(f"{name}: {said}")
    if not answers:
        print(f"appmode: no car answered: nothing was stopped{trust.refusal()}", file=sys.stderr)
        return 1
    return 0 if all(a.get("sent") and a.get("confirmed") is not False for a in answers) else 1
