"""The host client API over links: parameters, send, records, lost links, Z on close."""

from __future__ import annotations

import contextlib
import os
import socket
import time
from pathlib import Path

import pytest
import serial

from appmode.errors import AppmodeError
from appmode.host.app.client import Host
from appmode.host.app.state import HostState
from appmode.host.events import LinkStatus
from appmode.ports.target import Target
from appmode.protocol.app import Attitude, ParamsRecord, Velocity
from appmode.protocol.render import out_of_range
from tests.support.processes import BoardProcess, board_process


def test_read_set_verify_save_over_sim() -> None:
    with Host("sim://?pace=0") as host:
        assert host.read_params()[0] == 500
        assert host.set_param(5, 42)[5] == 42
        with pytest.raises(ValueError, match="system_mode"):
            host.set_param(8, 7)


def test_read_params_times_out_with_a_clear_error() -> None:
    with Host("loop://") as host:  # a loop echoes {Q:P}: no C record ever comes
        start = time.monotonic()
        with pytest.raises(
            AppmodeError, match=r"is not a board: sent \{Q:P\} 4 times; 20 bytes came back"
        ):
            host.read_params(timeout=0.2, tries=2)
        assert time.monotonic() - start < 2


def test_events_and_statistics_at_the_line_rate() -> None:
    with Host("sim://") as host:
        events = list(host.events(2.2))
        kinds = {type(e) for e in events}
        assert kinds == {Velocity, Attitude}
        # 44 in 2.2 s; a loaded machine reads late, and the window's ends catch a few
        # records more or less (47 beside five other workers)
        assert 40 <= len(events) <= 48, "about 20 records a second"
        stats = host.state.stats
        assert stats.records == len(events) and stats.errors == 0
        assert 15 <= stats.rate(host.now()) <= 21


def test_close_sends_z_last(tmp_path: Path) -> None:
    record = tmp_path / "board.transcript"
    with board_process("--listen", "0", "--quiet", "--record", str(record)) as board:
        host = Host(board.url)
        host.send(b"JA")
        host.poll(0.2)
        host.close()
    sent = [line.split(" ", 2)[2] for line in record.read_text().splitlines() if " > " in line]
    assert sent == ["J", "A", "Z"]


def test_board_keeps_state_between_clients() -> None:
    with board_process("--pty", "--no-pace", "--quiet") as board:
        with Host(board.url) as first:
            first.set_param(0, 900)
        with Host(board.url) as second:
            assert second.read_params()[0] == 900


def test_lost_link_is_reported_and_recovered_after_board_restart() -> None:
    first = BoardProcess("--listen", "127.0.0.1:0", "--quiet")
    port = first.url.rsplit(":", 1)[1]
    host = Host(first.url)
    try:
        host.read_params()
        first.kill()
        statuses: list[LinkStatus] = []
        restarted = None
        for event in host.events(8.0):
            if isinstance(event, LinkStatus):
                statuses.append(event)
                if not event.up and restarted is None:
                    restarted = BoardProcess("--listen", f"127.0.0.1:{port}", "--quiet")
                if event.up:
                    break
        assert [s.up for s in statuses] == [False, False, True], statuses
        assert "lost" in statuses[0].text and "back" in statuses[2].text
        assert "opens again; waiting for the board's output" in statuses[1].text
        assert host.read_params()[0] == 500
    finally:
        host.close()
        if restarted is not None:
            restarted.stop()


def test_second_tcp_client_is_refused_while_first_stays() -> None:
    with board_process("--listen", "0") as board:
        host, port = board.url[len("socket://") :].rsplit(":", 1)
        with Host(board.url) as first:
            first.read_params()
            with socket.create_connection((host, int(port)), timeout=3) as second:
                assert second.recv(100) == b"", "refused: closed at once"
            assert isinstance(first.read_params(), tuple)
        log = board.stop()
    assert "refused a client" in log and "one client at a time" in log


def test_params_record_is_not_reported_unless_intact() -> None:
    with Host("loop://") as host:
        host.send(b"{C500:10000:20:0:10:10:10:0:0}$")  # echoed back: a C record
        events = host.poll(0.5) + host.poll(0.1)
        assert any(isinstance(e, ParamsRecord) for e in events)
        host.send(b"{C500:10000:20:0:10:10:10:0:x}$")  # garbled: not a C record
        events = host.poll(0.5) + host.poll(0.1)
        assert not any(isinstance(e, ParamsRecord) for e in events)
        assert host.state.stats.errors >= 1


def test_a_board_holding_values_out_of_range_is_read_and_shown() -> None:
    with Host("loop://") as host:  # a board that took drive type 7 and a negative gain
        host.send(b"{C500:10000:20:-25:10:10:10:0:7}$")
        events = host.poll(0.5) + host.poll(0.1)
        [record] = [e for e in events if isinstance(e, ParamsRecord)]
        assert out_of_range(record.values) == ("position_ki", "system_mode")
        assert host.state.params == record


def test_a_record_caught_half_way_at_the_start_is_no_error() -> None:
    """Issue 23.2: a link opened mid-record showed DEGRADED (`1 errors in 5 s`)."""
    state = HostState()
    state.feed(b"0:0}$", 0.0)
    state.feed(b"{A0:0:0:0}$", 0.05)
    assert (state.stats.errors, state.stats.skipped, state.stats.recent_errors(0.1)) == (0, 5, 0)
    state.feed(b"0:0}${A0:0:0:0}$", 0.1)  # once records flow, the same bytes are an error
    assert state.stats.errors == 1
    state.reset_decoder()  # the link was lost: a new start
    state.feed(b"0}${B0:0:0:100}$", 0.2)
    assert state.stats.errors == 1


def test_a_path_that_opens_again_without_a_board_is_not_back(tmp_path: Path) -> None:
    """Issue 23.6: a pty path left by a board that died may lead to another program's
    pty. The host opens it again but says the link is back only when records come; until
    then it is not connected (a console does not drive into it)."""
    import pty

    with board_process("--pty", "--quiet") as board:
        link = tmp_path / "car"
        link.symlink_to(board.url)
        host = Host(str(link))
        try:
            seen, until = False, time.monotonic() + 5.0  # a loaded machine: its first
            while not seen and time.monotonic() < until:
                seen = any(isinstance(e, Velocity) for e in host.poll(1.0))
            assert seen
            master, slave = pty.openpty()  # another program's pty
            try:
                board.kill()
                link.unlink()  # at once: /dev/pts/N may be a new board's soon (a test beside)
                statuses = [e for e in host.events(0.6) if isinstance(e, LinkStatus)]
                link.symlink_to(os.ttyname(slave))
                statuses += [e for e in host.events(1.5) if isinstance(e, LinkStatus)]
                assert not host.connected and host.link is not None, "open, not proven"
                assert not any(s.up for s in statuses), statuses
                assert "waiting for the board's output" in statuses[-1].text
                os.write(master, b"{A0:0:0:0}$")
                statuses = [e for e in host.events(0.5) if isinstance(e, LinkStatus)]
                assert host.connected and statuses[-1].up, "records came: back"
            finally:
                os.close(master)
                os.close(slave)
        finally:
            host.close()


def test_a_numbered_pty_that_is_gone_is_never_opened_again() -> None:
    """A pty's number names the next pty made once it is gone, another program's: a host
    that opened /dev/pts/N again wrote its closing stops (`ZZ`, `{}KJZ`) into a test's
    terminal (CI). A link (as `board --link` keeps) may be reopened; the number is not."""
    import pty
    import tty

    from appmode.ports.target import parse_target
    from appmode.ports.urls import open_link

    assert parse_target("/dev/pts/4").numbered_pty and parse_target("/dev/ttys004").numbered_pty
    assert not parse_target("/dev/ttyUSB0").numbered_pty
    assert not parse_target("/tmp/car").numbered_pty
    master, slave = pty.openpty()
    tty.setraw(slave)
    path = os.ttyname(slave)
    opened: list[str] = []

    def opener(url: Target) -> serial.SerialBase:
        opened.append(url.url)
        return open_link(url)

    host = Host(path, opener=opener)
    try:
        os.write(master, b"{A0:0:0:0}$")
        assert any(isinstance(e, Velocity) for e in host.poll(1.0))
        os.close(master)  # the board's end: the pty is gone
        os.close(slave)
        others = [pty.openpty() for _ in range(4)]  # new ptys: one likely takes its number
        try:
            statuses = [e for e in host.events(1.5) if isinstance(e, LinkStatus)]
            assert statuses and not statuses[0].up and "not reopened" in statuses[0].text
            assert opened == [path], "opened once, never again"
            assert host.close() is None  # nothing sent: the link is down
            for other_master, _ in others:
                os.set_blocking(other_master, False)
                with contextlib.suppress(BlockingIOError):
                    assert os.read(other_master, 100) == b"", "nothing written to another pty"
        finally:
            for fds in others:
                for fd in fds:
                    os.close(fd)
    finally:
        host.close()


def test_a_second_client_of_a_tcp_board_is_told_it_was_refused() -> None:
    """Issue 23.2: it waited 5.8 s and said no parameters came back."""
    with board_process("--listen", "0", "--quiet") as board:
        first = Host(board.url)
        try:
            assert first.read_params()
            second = Host(board.url)
            try:
                started = time.monotonic()
                with pytest.raises(AppmodeError, match="serves one client at a time"):
                    second.read_params()
                assert time.monotonic() - started < 3.0
            finally:
                second.close()
        finally:
            first.close()
