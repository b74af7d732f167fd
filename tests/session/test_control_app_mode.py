"""APP mode on the control port (issue 64.1): with system_mode bit 7 set, UART2 takes APP
letters; the session counts them as motion, stops them with what the board obeys in the
mode it is in, and notices when the board leaves APP mode (a reset, or a set from the
APP port). Every stop is judged on the board's own state and recording."""

from __future__ import annotations

import time
from collections.abc import Callable
from pathlib import Path

import serial

from appmode.host.control.state import APP_QUIET
from appmode.session.control.session import ControlSession
from appmode.session.hold import HoldToDrive
from appmode.testing.served import ServedBoard
from tests.support.sessions import session as open_board

LEASE = 0.25
"""A page's heartbeat lease (web.bridge.HEARTBEAT)."""
ZERO = "FF FE 01 00 00 00 00 00 00 00"


def run(session: ControlSession, seconds: float, alive: bool = True) -> None:
    """Tick the session for `seconds`, its page beating (`alive`) or silent."""
    end = time.monotonic() + seconds
    while time.monotonic() < end:
        if alive:
            session.keepalive()
        session.tick()
        time.sleep(0.01)


def until(session: ControlSession, done: Callable[[], bool], what: str, timeout: float = 5) -> None:
    """Tick, beating, until `done()`; AssertionError naming `what` and the messages."""
    end = time.monotonic() + timeout
    while not done():
        assert time.monotonic() < end, f"no {what} in {timeout:g} s: {list(session.messages)}"
        run(session, 0.02)


def page_session(board: ServedBoard) -> ControlSession:
    """A session over the board's UART2 as `appmode web --uart2` makes it: a held key
    lasts a lease, and any motion only while the page beats."""
    session = open_board(board.uart2, HoldToDrive(LEASE, LEASE), uart2=True)
    assert isinstance(session, ControlSession)
    session.lease = LEASE
    session.start()
    until(session, lambda: session.baseline is not None and not session.busy, "settings read")
    return session


def app_mode_on(session: ControlSession) -> None:
    session.run("set system_mode 192")
    until(session, lambda: session.host.state.app_mode and not session.busy, "APP mode")


def sent_after(board: ServedBoard, since: float) -> list[str]:
    """What the board took on UART2 since `since` (its clock), a unit a line."""
    return [e.text for e in board.recording().entries if e.direction == "2>" and e.time > since]


def test_a_letter_sent_in_app_mode_stops_when_the_page_falls_silent(tmp_path: Path) -> None:
    with ServedBoard(tmp_path) as board:
        session = page_session(board)
        try:
            app_mode_on(session)
            session.run("send 41")  # an A
            board.wait_until(lambda s: s.velocity[1] > 0, 2, "forward on the letter")
            shown = session.instruments().in_force
            run(session, 0.3)  # still beating: still driving
            assert board.state.velocity[1] > 0
            silent_at = board.state.time
            started = time.monotonic()
            while board.state.moving:  # the page falls silent
                assert time.monotonic() - started < 1.0, "still moving 1 s after the silence"
                run(session, 0.02, alive=False)
            assert sent_after(board, silent_at)[-1] == "Z"
            assert shown == "A forward (APP letter)" and not session.moving
            assert any("no heartbeat" in m for m in session.messages)
            said = [m for m in session.messages if m.startswith("set system_mode = 192")]
            assert said and "APP mode on" in said[0], list(session.messages)
        finally:
            session.close()
        assert session.undelivered is None


def test_after_a_reset_the_session_reads_the_mode_again_and_its_stop_works(
    tmp_path: Path,
) -> None:
    with ServedBoard(tmp_path) as board:
        session = page_session(board)
        try:
            app_mode_on(session)
            board.restart()  # APP mode is never saved: UART2 reads frames again
            until(session, lambda: not session.host.state.app_mode, "left APP mode", 2 * APP_QUIET)
            assert any("left APP mode" in m for m in session.messages)
            until(session, lambda: session.host.state.report is not None, "encoder report")
            session.press("forward")  # a velocity frame, as before APP mode
            board.wait_until(lambda s: s.velocity[1] > 0, 2, "forward")
            started = time.monotonic()
            while board.state.moving:  # the key is let go
                assert time.monotonic() - started < 1.0, "still moving 1 s after the key"
                run(session, 0.02)
            assert not any("rejected" in line and "5A" in line for line in board.log)
        finally:
            session.close()
        assert sent_after(board, 0)[-1] == ZERO


def test_app_mode_cleared_from_the_app_port_the_stop_still_works(tmp_path: Path) -> None:
    with ServedBoard(tmp_path) as board:
        session = page_session(board)
        try:
            session.press("forward")  # a velocity frame in force
            board.wait_until(lambda s: s.velocity[1] > 0, 2, "forward")
            app_mode_on(session)
            with serial.Serial(board.port, 9600, timeout=1) as app_port:
                app_port.write(b"{8:64}")  # bit 7 off from the APP port
                until(session, lambda: not session.host.state.app_mode, "left APP mode", 3)
            session.run("send 41")  # the session may not know the mode: an A, then silence
            silent_at = board.state.time
            started = time.monotonic()
            while board.state.moving or time.monotonic() - started < 2 * LEASE:
                assert time.monotonic() - started < 1.5, "still moving after the silence"
                run(session, 0.02, alive=False)
            sent = sent_after(board, silent_at)
            assert ZERO in sent, sent  # the stop the board obeys in either mode
        finally:
            session.close()


def test_a_set_in_app_mode_goes_as_an_app_frame_and_frames_come_back(tmp_path: Path) -> None:
    with ServedBoard(tmp_path) as board:
        session = page_session(board)
        try:
            app_mode_on(session)
            session.run("set max_speed 800")
            assert "APP mode" in session.messages[-1]  # refused: nothing sent
            session.run("set system_mode 64")
            until(session, lambda: not session.busy and not session.host.state.app_mode, "mode")
            assert any(m.startswith("system_mode = 64") for m in session.messages), list(
                session.messages
            )
            assert board.state.params["system_mode"] == 64
        finally:
            session.close()
        sent = sent_after(board, 0)
        assert "{8:64}" in sent, sent[-20:]
