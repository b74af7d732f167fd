"""`appmode board`: serve the simulated board on a pseudo-terminal, TCP or a serial port."""

from __future__ import annotations

import argparse
import time
from functools import partial
from typing import TYPE_CHECKING

from appmode.cli.commands import COMMANDS
from appmode.cli.live_view import add_foxglove, live_view
from appmode.cli.options import (
    Subparsers,
    add_admission,
    add_profile,
    add_record,
    file_name,
    listen,
    number_type,
)
from appmode.errors import AppmodeError, install_line
from appmode.protocol.drive_types import DRIVE_NAMES

ADVERTISED_NAME = "HC-08"
"""The name a BLE module ships with, and the vendor's app lists."""

if TYPE_CHECKING:
    from types import ModuleType

    from appmode.ports.endpoints import MakeEndpoint


def register(sub: Subparsers) -> argparse.ArgumentParser:
    board = sub.add_parser(
        "board",
        help=COMMANDS["board"],
        description="Serve the simulated board so that any serial program (the phone app "
        "through a Bluetooth module, miniterm, appmode itself) can talk to it. Prints "
        "'port: URL' (the APP port, UART3 at 9600 bps) and 'uart2: URL' (the control "
        "port, UART2 at 115200 bps; see appmode protocol 8) for clients to open, then logs "
        "what it receives, port by port, until Ctrl-C.",
    )
    _add_where(board)
    board.add_argument(
        "--count",
        type=number_type(1, 1000, whole=True),
        default=1,
        metavar="N",
        help="serve N boards, each on its own pty, from this one process (default 1)",
    )
    board.add_argument(
        "--link",
        type=file_name,
        metavar="PATH",
        help="with --pty: keep a symlink PATH to the pty, and PATH.uart2 to the control "
        "port's, so clients find a restarted board at the same paths",
    )
    add_profile(
        board,
        "the board's behaviour: sheet (the vendor's sheet, the default), minibalance (the "
        "reference firmware as measured; see appmode protocol 13), or balance or a profile "
        "FILE: its records and parameters as declared, with no physics",
    )
    board.add_argument(
        "--drive", choices=DRIVE_NAMES, help="drive type (default: the saved one, else omni)"
    )
    board.add_argument(
        "--flash",
        type=file_name,
        metavar="FILE",
        help="keep saved parameters in this JSON file (default: in memory)",
    )
    board.add_argument(
        "--no-pace",
        action="store_true",
        help="send as fast as the link takes, not at the line rates (9600 bps on the APP "
        "port, 115200 on UART2)",
    )
    add_record(board)
    add_foxglove(board, "the board's own view (what both its ports carry)")
    board.add_argument(
        "--quiet", "-q", action="store_true", help="do not log what the board receives"
    )
    return board


def _add_where(board: argparse.ArgumentParser) -> None:
    """Where each port is served, and the APP port's rate."""
    where = board.add_mutually_exclusive_group()
    where.add_argument(
        "--pty", action="store_true", help="serve on a new pseudo-terminal (the default)"
    )
    where.add_argument(
        "--listen",
        type=listen("--listen"),
        metavar="HOST:PORT",
        help="serve on TCP, one client at a time (host 127.0.0.1 by default, [::1] for "
        "IPv6; port 0 picks a free one)",
    )
    where.add_argument(
        "--bluetooth",
        action="store_true",
        help="serve as a Bluetooth module (BLE HC-08 and classic HC-05) through a BlueZ "
        "stand-in on a private D-Bus bus: prints 'bus: ADDRESS' for "
        "DBUS_SYSTEM_BUS_ADDRESS (Linux, needs dbus-daemon and the bluetooth extra)",
    )
    where.add_argument(
        "--advertise",
        nargs="?",
        const=ADVERTISED_NAME,
        type=_advertised_name,
        metavar="NAME",
        help=f"serve as a Bluetooth module on this machine's adapter, for a phone (the "
        f"vendor's app) to connect to: advertised on BLE as NAME (default {ADVERTISED_NAME}) "
        "and offered as a classic SPP server (Linux with BlueZ; pair the phone first for SPP)",
    )
    where.add_argument(
        "--port",
        metavar="DEV",
        help="serve on a real serial port, e.g. /dev/ttyUSB0 (?baud=N to change 9600)",
    )
    where2 = board.add_mutually_exclusive_group()
    where2.add_argument(
        "--listen2",
        type=listen("--listen2"),
        metavar="HOST:PORT",
        help="serve UART2, the control port, on TCP (default: a second pseudo-terminal)",
    )
    where2.add_argument(
        "--port2",
        metavar="DEV",
        help="serve UART2 on a real serial port (?baud=N to change 115200)",
    )
    where3 = board.add_mutually_exclusive_group()
    where3.add_argument(
        "--listen-chassis",
        type=listen("--listen-chassis"),
        metavar="HOST:PORT",
        help="serve a WHEELTEC profile's chassis port on TCP (default: a pseudo-terminal)",
    )
    where3.add_argument(
        "--port-chassis",
        metavar="DEV",
        help="serve the chassis port on a real serial port (?baud=N to change 115200)",
    )
    board.add_argument(
        "--nus",
        action="store_true",
        help="with --advertise: offer the Nordic UART service instead of FFE0/FFE1",
    )
    add_admission(board)
    board.add_argument(
        "--baud",
        type=number_type(300, 4_000_000, whole=True),
        metavar="N",
        help="the APP port's bit rate (default 9600): a car whose Bluetooth module is set "
        "to another rate. It paces the port; on a pty, a client that opens it at another "
        "rate reads garbled bytes, as from a real UART (the UART2 pty likewise at 115200)",
    )


def run(args: argparse.Namespace) -> int:
    from appmode.board.profiles import profile_named
    from appmode.ports.serve import ServeOptions, run_board
    from appmode.protocol.params import DriveType

    alone = (
        args.listen,
        args.port,
        args.bluetooth or None,
        args.advertise,
        args.link,
        args.flash,
        args.record,
        args.listen2,
        args.port2,
        args.listen_chassis,
        args.port_chassis,
        args.foxglove,
    )
    if args.count > 1 and any(option is not None for option in alone):
        raise AppmodeError(
            "--count serves several boards on ptys: it cannot be combined "
            "with --listen, --port, --bluetooth, --advertise, --listen2, --port2, "
            "--listen-chassis, --port-chassis, --link, --flash, --record or --foxglove"
        )
    if (args.nus or args.allow or args.secure) and args.advertise is None:
        raise AppmodeError(
            "--nus, --allow and --secure are options of --advertise: add --advertise [NAME]"
        )
    profile = profile_named(args.profile)
    if profile.chassis is None and (args.listen_chassis or args.port_chassis):
        raise AppmodeError(
            f"the {profile.name} profile's board has no chassis port: add --profile "
            "wheeltec-mec (or wheeltec-akm, wheeltec-diff)"
        )
    options = ServeOptions(
        app=_app_endpoint(args),
        uart2=_uart2_endpoint(args),
        chassis=_chassis_endpoint(args) if profile.chassis is not None else None,
        count=args.count,
        profile=profile,
        drive=DriveType.from_cli_name(args.drive) if args.drive else None,
        flash=args.flash,
        pace=not args.no_pace,
        record=args.record,
        quiet=args.quiet,
        baud=args.baud,
    )
    drive = options.drive or (None if args.flash else DriveType.OMNI)  # else: the flash says
    with live_view(args.foxglove, options.profile.a_layout, drive_type=drive) as view:
        if view is not None:
            view.epoch = time.time()  # the board's clock starts now
        return run_board(options, view)


def _app_endpoint(args: argparse.Namespace) -> MakeEndpoint:
    from appmode.ports import endpoints
    from appmode.ports.urls import BAUD

    if args.listen is not None:
        host, port = args.listen
        return partial(endpoints.TcpEndpoint, host=host, port=port, baud=args.baud)
    if args.port is not None:
        return partial(endpoints.SerialEndpoint, device=args.port, baud=args.baud or BAUD)
    if args.bluetooth:
        return partial(_bluetooth("--bluetooth").BluetoothEndpoint, baud=args.baud)
    if args.advertise is not None:
        from appmode.bluetooth.advertise.admission import Admission
        from appmode.bluetooth.uuids import UART_SERVICES

        endpoint = _bluetooth("--advertise").AdvertisedEndpoint
        service = UART_SERVICES[1 if args.nus else 0]
        admission = Admission(frozenset(args.allow or ()), args.secure)
        return partial(
            endpoint, name=args.advertise, service=service, baud=args.baud, admission=admission
        )
    return partial(endpoints.PtyEndpoint, link=args.link, baud=args.baud)


def _advertised_name(text: str) -> str:
    from appmode.bluetooth.advertise.module_name import name_problem

    if (why := name_problem(text)) is not None:
        raise argparse.ArgumentTypeError(why)
    return text


def _bluetooth(option: str) -> ModuleType:
    """The stand-in's endpoint module, or one line on what to install and what it runs on."""
    from appmode.bluetooth.availability import unsupported

    if (why := unsupported()) is not None:
        raise AppmodeError(f"{option}: {why}")
    try:
        from appmode.bluetooth.standin import endpoint
    except ImportError:
        raise AppmodeError(
            f"{option} needs the bluetooth extra: {install_line('bluetooth')}"
        ) from None
    return endpoint


def _uart2_endpoint(args: argparse.Namespace) -> MakeEndpoint:
    from appmode.line.wire import UART2_BAUD
    from appmode.ports import endpoints

    if args.listen2 is not None:
        host, port = args.listen2
        return partial(endpoints.TcpEndpoint, host=host, port=port, baud=None)
    if args.port2 is not None:
        return partial(endpoints.SerialEndpoint, device=args.port2, baud=UART2_BAUD)
    link = f"{args.link}.uart2" if args.link else None  # the control port's stable name
    return partial(endpoints.PtyEndpoint, link=link, baud=UART2_BAUD if args.baud else None)


def _chassis_endpoint(args: argparse.Namespace) -> MakeEndpoint:
    from appmode.line.wire import CHASSIS_BAUD
    from appmode.ports import endpoints

    if args.listen_chassis is not None:
        host, port = args.listen_chassis
        return partial(endpoints.TcpEndpoint, host=host, port=port, baud=None)
    if args.port_chassis is not None:
        return partial(endpoints.SerialEndpoint, device=args.port_chassis, baud=CHASSIS_BAUD)
    link = f"{args.link}.chassis" if args.link else None  # the chassis port's stable name
    return partial(endpoints.PtyEndpoint, link=link, baud=CHASSIS_BAUD if args.baud else None)
