"""`appmode ports`: list the serial ports, and which look like a car's link."""

from __future__ import annotations

import argparse
import sys

from appmode.cli.commands import COMMANDS
from appmode.cli.options import Subparsers


def register(sub: Subparsers) -> argparse.ArgumentParser:
    return sub.add_parser(
        "ports",
        help=COMMANDS["ports"],
        description="List the serial ports of this machine (device, description, hardware "
        "id), marking those that look like a car's link: a USB-UART adapter or a "
        "Bluetooth serial port. Give the device to any command as its URL.",
    )


def run(args: argparse.Namespace) -> int:
    from appmode.ports.listing import serial_ports

    ports = serial_ports()
    out = sys.stdout
    if not ports:
        out.write(
            "no serial ports found: plug in the USB-UART adapter, or bind the car's "
            "Bluetooth module (appmode doctor /dev/rfcomm0 says how); "
            "'appmode board --pty' serves a simulated board\n"
        )
        return 0
    width = max(len(p.device) for p in ports)
    for port in ports:
        mark = f"  [{port.kind}]" if port.kind else ""
        out.write(f"{port.device.ljust(width)}  {port.description}{mark}\n")
        if port.hwid:
            out.write(f"{' ' * width}  {port.hwid}\n")
    return 0
