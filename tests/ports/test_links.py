"""Links by URL (docs/design.md): every URL kind, sim:// for pyserial, and clear open errors."""

from __future__ import annotations

import errno
import os
import pty
import socket
import tty

import pytest
import serial

import appmode  # noqa: F401 - registers sim://
from appmode.errors import AppmodeError
from appmode.host.app.client import Host
from appmode.ports.urls import explain_open_error, open_link
from tests.support.processes import board_process
from tests.support.rfc2217_server import Rfc2217Server

DEFAULTS = (500, 10000, 20, 0, 10, 10, 10, 0, 0)


def test_sim_url_opens_in_any_pyserial_program() -> None:
    port = serial.serial_for_url("sim://?pace=0", timeout=0.3)
    port.write(b"{Q:P}")
    data = port.read(200)
    port.close()
    assert b"{C500:10000:20:0:10:10:10:0:0}$" in data


def test_sim_url_options_drive_flash_pace(tmp_path: object) -> None:
    flash = f"{tmp_path}/f.json"
    with Host(f"sim://?drive=diff-gyro&flash={flash}&pace=0") as host:
        assert host.read_params()[8] == 3
        host.set_param(0, 800)
        host.save()
        host.read_params()
    with Host(f"sim://?flash={flash}") as host:
        assert host.read_params()[0] == 800


@pytest.mark.parametrize(
    ("url", "message"),
    [
        ("sim://?drive=tank", "unknown drive type 'tank'"),
        ("sim://?speed=3", "unknown sim:// option 'speed'"),
        ("sim://?pace=maybe", "use 1 or 0"),
        ("sim://somewhere", "expected sim://"),
        ("ftp://host", "unknown URL scheme 'ftp://'"),
        ("/dev/does-not-exist", "no such port /dev/does-not-exist"),
        ("/dev/pts/0?parity=E", "only ?baud=N is known"),
        ("/dev/pts/0?baud=fast", "bad baud rate"),
    ],
)
def test_bad_urls_say_what_to_do(url: str, message: str) -> None:
    with pytest.raises(AppmodeError, match=message.replace("?", r"\?")):
        open_link(url)


def test_a_pty_path_opens_as_a_real_port_at_9600() -> None:
    master, slave = pty.openpty()
    tty.setraw(slave)
    path = os.ttyname(slave)
    port = open_link(path)
    assert port.baudrate == 9600 and (port.bytesize, port.parity, port.stopbits) == (8, "N", 1)
    port.write(b"J")
    assert os.read(master, 10) == b"J"
    port.close()
    fast = open_link(path + "?baud=115200")
    assert fast.baudrate == 115200
    fast.close()
    os.close(master)
    os.close(slave)


def test_a_busy_port_is_reported() -> None:
    master, slave = pty.openpty()
    path = os.ttyname(slave)
    first = open_link(path)
    with pytest.raises(AppmodeError, match="is busy: another program has it open"):
        open_link(path)
    first.close()
    os.close(master)
    os.close(slave)


def test_permission_and_refusal_messages() -> None:
    denied = serial.SerialException(errno.EACCES, "could not open port: Permission denied")
    assert "add yourself to the dialout group" in explain_open_error("/dev/ttyUSB0", denied)
    refused = serial.SerialException("Could not open port: [Errno 111] Connection refused")
    assert "nothing is listening" in explain_open_error("socket://h:1", refused)


def test_nothing_listening_on_tcp() -> None:
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        port = probe.getsockname()[1]
    with pytest.raises(AppmodeError, match=r"nothing is listening at socket://127\.0\.0\.1"):
        open_link(f"socket://127.0.0.1:{port}")


def test_loop_url_opens() -> None:
    port = open_link("loop://")
    port.write(b"{A1:2:3:0}$")
    assert port.read(11) == b"{A1:2:3:0}$"
    port.close()


def test_rfc2217_url_reaches_the_simulated_board() -> None:
    sim = serial.serial_for_url("sim://?pace=0", timeout=0.05)
    server = Rfc2217Server(sim)
    try:
        with Host(server.url) as host:
            assert host.read_params() == DEFAULTS
    finally:
        server.close()
        sim.close()


def test_pty_board_process_over_device_path() -> None:
    with board_process("--pty", "--no-pace", "--quiet") as board, Host(board.url) as host:
        assert board.url.startswith("/dev/")
        assert host.read_params() == DEFAULTS


def test_tcp_board_process_over_socket_url() -> None:
    with board_process("--listen", "127.0.0.1:0", "--quiet") as board, Host(board.url) as host:
        assert board.url.startswith("socket://127.0.0.1:")
        assert host.set_param(0, 700)[0] == 700
