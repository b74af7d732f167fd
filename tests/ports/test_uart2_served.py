"""The board's control port served for real (docs/protocol.md §8): a second pty beside
the APP port, a plain pyserial client, and sim:// opening both ports of one board."""

from __future__ import annotations

import signal
import time
from pathlib import Path

import serial

from appmode.protocol import app, app_decoders, control
from appmode.protocol.params import DriveType
from tests.support.processes import board_process, run

READ_MAX_SPEED = bytes.fromhex("FF FE 80 80 11 00 00 00 00 00")


def a_records(port: serial.Serial, seconds: float) -> list[app.Velocity]:
    port.reset_input_buffer()
    time.sleep(seconds)
    events = app_decoders.BoardDecoder().feed(port.read(port.in_waiting))
    return [e for e in events if isinstance(e, app.Velocity)]


def test_board_serves_uart2_and_a_plain_pyserial_script_uses_it(tmp_path: Path) -> None:
    record = tmp_path / "both.transcript"
    with board_process("--pty", "--record", str(record)) as board:
        assert board.uart2.startswith("/dev/") and board.uart2 != board.url
        with (
            serial.Serial(board.uart2, 115200, timeout=1) as u2,
            serial.Serial(board.url, 9600, timeout=1) as uart3,
        ):
            u2.write(READ_MAX_SPEED)
            assert u2.read(6) == bytes.fromhex("23 01 00 00 01 F4")
            u2.write(bytes.fromhex("FF FE 01 00 00 01 2C 00 00 00"))  # y = 300
            time.sleep(1.0)
            assert a_records(uart3, 0.3)[-1].y == 300, "the APP port's A record follows"
            u2.write(control.STOP)
            uart3.write(b"JA")  # after the take-over the letters do not drive
            time.sleep(1.0)
            assert {r.y for r in a_records(uart3, 0.3)} == {0}
        log = board.stop()
    assert "uart2 info     UART2 takes over the motion at its byte 10" in log
    assert "uart3 rejected A: ignored: UART2 drives (§8.3)" in log
    lines = record.read_text().splitlines()
    assert any(line.endswith("2> FF FE 80 80 11 00 00 00 00 00") for line in lines)
    assert any(line.endswith("2< 23 01 00 00 01 F4") for line in lines)
    dumped = run("dump", str(record))
    assert "reply max_speed = 500" in dumped.stdout


def test_uart2_is_paced_at_115200_never_early() -> None:
    reads = 200  # 2,000 bytes in: 174 ms of wire at 115200 bps, however fast they are sent
    with (
        board_process("--pty", "--quiet") as board,
        serial.Serial(board.uart2, 115200, timeout=1) as u2,
    ):
        start = time.monotonic()
        u2.write(READ_MAX_SPEED * reads)
        got = b""
        while len(got) < 6 * reads and time.monotonic() - start < 5:
            got += u2.read(6 * reads - len(got))
        elapsed = time.monotonic() - start
    assert got == bytes.fromhex("23 01 00 00 01 F4") * reads
    assert len(READ_MAX_SPEED) * reads * 10 / 115200 <= elapsed < 1.0


def test_sim_share_opens_both_ports_of_one_board() -> None:
    url = "sim://?share=t1&pace=0"
    with (
        serial.serial_for_url(url, timeout=0.5) as uart3,
        serial.serial_for_url(url + "&port=uart2", timeout=0.5) as u2,
    ):
        assert uart3.board is u2.board
        uart3.write(b"JA")
        u2.write(control.encode(control.velocity(DriveType.OMNI, y=120)))
        time.sleep(0.5)
        assert u2.in_waiting == 0  # the board runs when a port is used: no reply yet
        assert u2.board.uart2_control
        assert a_records(uart3, 0.3)[-1].y == 120
        u2.write(READ_MAX_SPEED)
        assert u2.read(6) == bytes.fromhex("23 01 00 00 01 F4")


def test_sim_share_refuses_a_port_opened_twice_or_other_options() -> None:
    with serial.serial_for_url("sim://?share=t2", timeout=0.1):
        for url, said in (
            ("sim://?share=t2", "app port is already open"),
            ("sim://?share=t2&drive=diff&port=uart2", "open this port with the same"),
        ):
            try:
                serial.serial_for_url(url, timeout=0.1)
            except serial.SerialException as exc:
                assert said in str(exc)
            else:
                raise AssertionError(f"{url} opened")


def test_a_second_of_garbage_at_115200_is_counted_and_the_board_keeps_serving() -> None:
    with serial.serial_for_url("sim://?share=flood&port=uart2", timeout=3) as u2:
        flood = bytes(range(256)) * 45  # 11,520 bytes: a second of the line
        u2.write(flood + READ_MAX_SPEED)
        assert u2.read(6) == bytes.fromhex("23 01 00 00 01 F4")
        assert u2.board.uart2_errors >= len(flood) // 64  # runs of at most 64 bytes
        assert u2.board.vehicle.vx == u2.board.vehicle.vy == u2.board.vehicle.vz == 0


def test_app_commands_refuse_the_control_port_of_a_sim_board() -> None:
    done = run("send", "sim://?port=uart2", "J", "A")
    assert done.returncode == 2
    assert done.stderr.count("\n") == 1 and "leave out port=uart2" in done.stderr


def test_what_a_client_wrote_before_the_board_ended_is_in_its_recording(tmp_path: Path) -> None:
    """A client's last frame (its stop) written just before the board ends is read and
    recorded on the way out: the board's recording, the tests' judge, holds it. The board
    is held still (SIGSTOP) while the frame is written and the end is asked for, so its
    serving loop never sees the frame."""
    record = tmp_path / "end.transcript"
    with (
        board_process("--pty", "--quiet", "--record", str(record)) as board,
        serial.Serial(board.uart2, 115200, timeout=1) as u2,
    ):
        board.proc.send_signal(signal.SIGSTOP)
        try:
            u2.write(control.STOP)
            u2.flush()
            board.proc.send_signal(signal.SIGTERM)
        finally:
            board.proc.send_signal(signal.SIGCONT)
        assert board.proc.wait(10) == 0
    lines = record.read_text().splitlines()
    assert lines[-1].endswith("2> " + control.STOP.hex(" ").upper()), lines[-3:]
