"""Issue 75.3: a URL scheme is one row of `ports.schemes.SCHEMES` and one
`protocol_<scheme>` module (pyserial's way), and nothing else lists the schemes."""

from __future__ import annotations

import importlib
from pathlib import Path

import serial

import appmode
from appmode.ports.schemes import SCHEMES, handler_packages
from appmode.ports.target import parse_target

PACKAGE = Path(appmode.__file__).parent


def test_every_protocol_module_is_a_row_and_every_row_s_module_is_a_port() -> None:
    modules = {
        ".".join(p.relative_to(PACKAGE.parent).with_suffix("").parts)
        for p in PACKAGE.rglob("protocol_*.py")
    }
    ports = {s.port for s in SCHEMES.values() if s.port is not None}
    assert modules == ports
    for name, scheme in SCHEMES.items():
        if scheme.port is not None:
            assert scheme.port.endswith(f".protocol_{'tcp' if name == 'socket' else name}")
            assert issubclass(importlib.import_module(scheme.port).Serial, serial.SerialBase)


def test_pyserial_opens_appmode_s_schemes_from_the_table() -> None:
    assert set(handler_packages()) <= set(serial.protocol_handler_packages)
    port = serial.serial_for_url("sim://")
    try:
        assert port.is_open
    finally:
        port.close()


def test_the_table_decides_what_an_address_is() -> None:
    assert parse_target("socket://localhost:7000").network
    assert parse_target("rfc2217://localhost:7000").network
    assert not parse_target("sim://").network
    assert parse_target("ble://AA:BB:CC:DD:EE:FF").radio is not None


def test_no_other_module_lists_the_schemes() -> None:
    listed = [
        p.relative_to(PACKAGE).as_posix()
        for p in PACKAGE.rglob("*.py")
        if p.name != "schemes.py" and '"rfc2217"' in p.read_text(encoding="utf-8")
    ]
    assert not listed, listed
