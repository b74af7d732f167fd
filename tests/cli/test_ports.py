"""`appmode ports` lists the serial ports and marks those that look like a car's link."""

from __future__ import annotations

import pytest
from serial.tools import list_ports
from serial.tools.list_ports_common import ListPortInfo

from appmode.cli.main import main


def _port(
    device: str, description: str = "n/a", vid: int | None = None, pid: int | None = None
) -> ListPortInfo:
    info = ListPortInfo(device, skip_link_detection=True)
    info.description = description
    if vid is not None:
        info.vid, info.pid = vid, pid
        info.hwid = f"USB VID:PID={vid:04X}:{pid:04X} LOCATION=1-1"
    return info


def test_adapters_and_bluetooth_come_first_and_are_marked(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    found = [
        _port("/dev/ttyS0"),
        _port("/dev/rfcomm0"),
        _port("/dev/ttyUSB0", "USB Serial", 0x1A86, 0x7523),
    ]
    monkeypatch.setattr(list_ports, "comports", lambda include_links=False: found)
    assert main(["ports"]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert lines[0].startswith("/dev/rfcomm0") and lines[0].endswith("[Bluetooth serial]")
    assert lines[1].startswith("/dev/ttyUSB0") and "USB Serial  [CH340 USB-UART]" in lines[1]
    assert "VID:PID=1A86:7523" in lines[2]
    assert lines[3].rstrip() == "/dev/ttyS0"


def test_no_ports_says_what_to_do(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    monkeypatch.setattr(list_ports, "comports", lambda include_links=False: [])
    assert main(["ports"]) == 0
    out = capsys.readouterr().out
    assert out.startswith("no serial ports found: plug in the USB-UART adapter")
    assert "appmode board --pty" in out
