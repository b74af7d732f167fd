"""The host over the control port (UART2): reads that agree, verified sets, motion,
rotation, the encoder report, and the stop frame last whatever ends the session."""

from __future__ import annotations

import pytest

from appmode.errors import AppmodeError
from appmode.host.app.client import Host
from appmode.host.control.client import ControlHost
from appmode.ports.target import parse_target
from appmode.protocol import app, control, params, settings
from appmode.protocol.transcript import UART2_DIRECTIONS


def tapped(host: ControlHost) -> list[tuple[str, bytes]]:
    seen: list[tuple[str, bytes]] = []
    host.tap = lambda direction, now, data: seen.append((direction, data))
    return seen


def test_uart2_url_opens_the_simulated_control_port() -> None:
    assert parse_target("sim://").for_uart2().url == "sim://?port=uart2"
    assert parse_target("sim://?drive=diff").for_uart2().url == "sim://?drive=diff&port=uart2"
    assert parse_target("/dev/ttyUSB0").for_uart2().url == "/dev/ttyUSB0"
    assert ControlHost("sim://?drive=diff").url == "sim://?drive=diff&port=uart2"
    with pytest.raises(AppmodeError, match="APP port"):
        ControlHost("sim://?port=app")


def test_the_ten_settings_read_set_verified_and_defaults() -> None:
    with ControlHost("sim://?drive=mecanum") as host:
        values = host.settings()
        assert list(values) == [s.name for s in settings.SETTINGS]
        assert values["max_speed"] == 500 and values["system_mode"] == 1
        assert host.set("max_speed", 800) == 800
        assert host.read("max_speed") == 800
        with pytest.raises(AppmodeError, match="0–65535"):
            host.set("max_speed", 70000)
        assert host.drive is params.DriveType.MECANUM
        host.store("defaults")
        assert host.read("max_speed") == 500
        assert host.drive is params.DriveType.OMNI, "the factory drive type, read again"


def test_velocity_drives_the_car_and_the_app_port_follows() -> None:
    with (
        ControlHost("sim://?share=v&drive=mecanum") as host,
        Host("sim://?share=v&drive=mecanum") as app_port,
    ):
        host.set_mode_bit("encoder_report", True)
        host.velocity(y=300)
        reports = list(host.reports(0.6))
        assert len(reports) >= 8, "a report every 50 ms"
        assert reports[-1].targets == (300,) * 4 and reports[-1].actuals[0] > 250
        records = [e for e in app_port.events(0.3) if isinstance(e, app.Velocity)]
        assert records and records[-1].y > 250
        assert host.encoders()["speed_a"] > 250


def test_rotate_waits_for_the_pending_angle() -> None:
    with ControlHost("sim://?drive=omni") as host:
        took = host.rotate(30)
        assert 0.2 < took < 5 and host.pending_angle() == 0


def test_close_sends_the_stop_frame_last_after_completing_an_open_frame() -> None:
    with (
        ControlHost("sim://?share=c&drive=mecanum") as host,
        Host("sim://?share=c&drive=mecanum") as app_port,
    ):
        seen = tapped(host)
        host.velocity(y=300)
        host.send(bytes.fromhex("FF FE 01 03"))  # a raw frame left open
        list(app_port.events(0.5))
        stop = host.close()
        assert stop == bytes(6) + control.STOP
        assert seen[-1] == ("2>", stop) and seen[-1][0] in UART2_DIRECTIONS
        records = [e for e in app_port.events(1.5) if isinstance(e, app.Velocity)]
        assert records[-1] == app.Velocity(0, 0, 0, 0), "the car stopped"


def test_a_frame_after_raw_bytes_is_read_whole() -> None:
    with ControlHost("sim://?drive=mecanum") as host:
        host.send(bytes.fromhex("FF FE 80"))
        assert host.set("max_speed", 700) == 700


def test_a_board_that_does_not_answer_gives_one_clear_error() -> None:
    with (
        ControlHost("sim://?profile=minibalance", timeout=0.05, tries=3) as host,
        pytest.raises(AppmodeError, match=r"no reply reading max_speed .* after 3 tries"),
    ):
        host.read("max_speed")


def test_reads_agree_on_a_noisy_link() -> None:
    """What a read reports is the board's value, whatever the noise did to the replies.
    (A frame to the board has no checksum: noise may make a read a set, whose value is
    then the board's: the read is checked against the board's before and after it.)"""
    url = "sim://?drive=mecanum&faults=corrupt:0.01,drop:0.01,seed:4"
    with ControlHost(url, tries=20) as host:
        board = host._port.board
        for _ in range(5):
            before = board.core.params[params.MAX_SPEED]
            read = host.settings()["max_speed"]
            assert read in (before, board.core.params[params.MAX_SPEED])
