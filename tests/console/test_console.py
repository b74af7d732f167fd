"""The driving console, headless (create_pipe_input + DummyOutput) on the simulated board."""

from __future__ import annotations

import io
import sys
import threading
import time
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any
from unittest import mock

import pytest
from prompt_toolkit.input import create_pipe_input
from prompt_toolkit.output import DummyOutput

from appmode.console.driving import run_drive
from appmode.console.terminal import REDRAW, Console
from appmode.session.app.session import AppSession
from appmode.session.hold import HoldToDrive
from tests.support.sessions import session as open_board

UP = "\x1b[A"
CTRL_C = "\x03"


def sent(record: Path) -> list[tuple[float, str]]:
    """The host→board lines of a transcript: (time, payload)."""
    out = []
    for line in record.read_text().splitlines():
        if " > " in line:
            time_text, _, payload = line.split(" ", 2)
            out.append((float(time_text), payload))
    return out


class CountedOutput(DummyOutput):  # type: ignore[misc]
    """An output that notes when each drawing of the screen ended (a flush)."""

    def __init__(self) -> None:
        super().__init__()
        self.drawn: list[float] = []

    def flush(self) -> None:
        self.drawn.append(time.monotonic())


Seen = Callable[[Console], bool]
"""What a person waits to see after a key before the next (the menu open, say)."""


def run_console(
    tmp_path: Path,
    keys: list[tuple[str, float]] | list[tuple[str, float, Seen | None]],
    url: str = "sim://",
    output: DummyOutput | None = None,
    **driving: Any,
) -> tuple[AppSession, Path, list[float]]:
    """Run the console with `keys` typed (text, pause after, and what to see before the
    pause, if anything); returns when it has quit."""
    record = tmp_path / "app.transcript"
    session = open_board(url, HoldToDrive(**driving), str(record))
    assert isinstance(session, AppSession)
    typed_at: list[float] = []
    consoles: list[Console] = []

    class Watched(Console):
        def __init__(self, *args: Any) -> None:
            super().__init__(*args)
            consoles.append(self)

    def see(what: Seen | None) -> None:
        ready = time.monotonic() + 10
        while what is not None and not what(consoles[0]) and time.monotonic() < ready:
            time.sleep(0.01)

    with create_pipe_input() as pipe, mock.patch("appmode.console.driving.Console", Watched):

        def typist() -> None:
            # as a person does: types once the console has read the parameters (on a
            # loaded machine that took past the 0.5 s this waited, and a `set` was busy)
            ready = time.monotonic() + 10
            while "parameters read" not in session.messages and time.monotonic() < ready:
                time.sleep(0.01)
            time.sleep(0.1)
            for text, pause, *seen in keys:
                typed_at.append(session.host.now())
                pipe.send_text(text)
                see(*seen or [None])
                time.sleep(pause)

        thread = threading.Thread(target=typist, daemon=True)
        thread.start()
        run_drive(session, True, [], io.StringIO(), pipe, output or DummyOutput())
        thread.join(5)
    return session, record, typed_at


def said(text: str) -> Seen:
    """The console's session has said `text` (a set verified: on a loaded machine that
    can take past a fixed pause)."""
    return lambda console: text in console.session.messages


@pytest.fixture
def quit_key() -> Iterator[tuple[str, float]]:
    yield (CTRL_C, 0.0)


@pytest.mark.timing
def test_holding_up_drives_and_letting_go_stops(
    tmp_path: Path, quit_key: tuple[str, float]
) -> None:
    hold = [(UP, 0.03)] * 25  # the terminal's auto-repeat: ~33 presses a second
    _, record, typed = run_console(tmp_path, [*hold, ("", 0.6), quit_key])
    lines = sent(record)
    payloads = [p for _, p in lines]
    assert payloads[:2] == ["J", "{Q:P}"], "the console starts on the direction page"
    # repeats do not resend: an A again only after a stop (a lapse on a loaded machine
    # is stopped, as it must be, and the next repeat drives again)
    driving = payloads[payloads.index("A") :]
    pairs = zip(driving[1:], driving, strict=False)
    assert all(before == "Z" for letter, before in pairs if letter == "A"), payloads
    z_after = [t for t, p in lines if p == "Z" and t > typed[24]]
    release = z_after[0] - typed[24]
    # due 0.25 s after it (the repeat time-out, then the session's 0.1-s tick); a loaded
    # machine's scheduler may add a tenth and more to a wait: 0.394 s beside five workers
    assert 0.14 <= release <= 0.45, f"stopped {release:.3f} s after the last repeat"
    assert payloads[-1] == "Z"


def test_a_held_key_s_repeats_do_not_draw_the_screen_again(
    tmp_path: Path, quit_key: tuple[str, float]
) -> None:
    """A key held repeats some 33 times a second; only the press that drives redraws at
    once, the repeats leave the panel to its 0.1-s check (a console that drew 33 times a
    second used three times the CPU, and waited the longer for one on a busy machine)."""
    output = CountedOutput()
    hold = [(UP, 0.03)] * 30
    session, _, typed = run_console(tmp_path, [*hold, ("", 0.5), quit_key], output=output)
    offset = session.host.now() - time.monotonic()  # the session's clock from this one's
    during = [t + offset for t in output.drawn if typed[0] + 0.05 < t + offset < typed[29]]
    held = typed[29] - typed[0] - 0.05
    # the panel's check (REDRAW, 0.1 s) while telemetry changes it, and no more
    assert len(during) <= held / REDRAW + 2, (len(during), held)
    assert session.driving.current is None  # it drove, and stopped when let go


@pytest.mark.timing
def test_a_single_tap_stops_after_the_first_timeout(
    tmp_path: Path, quit_key: tuple[str, float]
) -> None:
    _, record, typed = run_console(tmp_path, [(UP, 2.0), quit_key], first_timeout=0.4)
    lines = sent(record)
    z_time = next(t for t, p in lines if p == "Z" and t > typed[0])
    # at its first timeout, not a repeat's (0.15 s) nor the quit's (2 s): on a machine
    # running a second suite beside this one the stop came 0.36 s late
    assert 0.38 <= z_time - typed[0] <= 1.0


def test_grid_keys_follow_the_page(tmp_path: Path, quit_key: tuple[str, float]) -> None:
    keys = [
        ("q", 0.1),
        (" ", 0.1),
        ("k", 0.1),
        ("q", 0.1),
        ("d", 0.1),
        (" ", 0.1),
        ("j", 0.1),
        ("c", 0.1),
        quit_key,
    ]
    _, record, _ = run_console(tmp_path, keys)
    letters = [p for _, p in sent(record) if not p.startswith("{")][1:]
    # direction page: q = H front-left; button page: q = B front-left, d = C rotate-cw
    expected = ["H", "Z", "K", "B", "C", "Z", "J", "D", "Z"]
    # the motions in order, each stop of the space bar and the quit's in its place; on a
    # loaded machine a key whose next came after its timeout was stopped before it, as it
    # must be: a stop more, and only a stop
    unexpected = letters.copy()
    for letter in expected:
        assert letter in unexpected, (letter, letters)
        at = unexpected.index(letter)
        assert set(unexpected[:at]) <= {"Z"}, letters
        del unexpected[: at + 1]
    assert set(unexpected) <= {"Z"}, letters


def test_command_line_set_is_verified_and_typing_does_not_drive(
    tmp_path: Path, quit_key: tuple[str, float]
) -> None:
    verified = said("max_speed = 800 (verified)")
    keys = [(":", 0.1, None), ("set max_speed 800\r", 0.1, verified), (*quit_key, None)]
    session, record, _ = run_console(tmp_path, keys)
    payloads = [p for _, p in sent(record)]
    assert "{0:800}" in payloads
    assert not set(payloads) & {"A", "B", "C", "D", "E", "F", "G", "H"}
    assert session.host.state.params is not None
    assert session.host.state.params.values[0] == 800
    assert "max_speed = 800 (verified)" in session.messages


def test_command_line_errors_are_messages(tmp_path: Path, quit_key: tuple[str, float]) -> None:
    keys = [(":", 0.1), ("set max_speed 99999\r", 0.2), (":", 0.1), ("fly\r", 0.2), quit_key]
    session, _, _ = run_console(tmp_path, keys)
    assert any("max_speed (parameter 0) must be in 0–65535" in m for m in session.messages)
    assert any("unknown command 'fly'" in m for m in session.messages)


def test_quit_command_sends_z_last_even_while_latched(tmp_path: Path) -> None:
    keys = [("l", 0.1), ("w", 0.5), (":", 0.1), ("quit\r", 0.0)]
    _, record, _ = run_console(tmp_path, keys)
    payloads = [p for _, p in sent(record)]
    assert "A" in payloads and payloads[-1] == "Z"


def test_a_crash_in_the_console_still_sends_z_last(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    calls = {"n": 0}
    real = AppSession.tick

    def failing_tick(self: AppSession) -> None:
        calls["n"] += 1
        if calls["n"] == 40:
            raise RuntimeError("boom")
        real(self)

    monkeypatch.setattr(AppSession, "tick", failing_tick)
    with pytest.raises(RuntimeError, match="boom"):
        run_console(tmp_path, [("w", 0.0), ("w", 5.0)], latched=True)
    payloads = [p for _, p in sent(tmp_path / "app.transcript")]
    assert "A" in payloads and payloads[-1] == "Z"


TAB = "\t"


@pytest.mark.parametrize("typed", ["params", "set max_speed 800", "page button"])
def test_up_recalls_the_previous_command_not_a_completion(tmp_path: Path, typed: str) -> None:
    # typed a key at a time; then `:`, Tab (the menu of commands), ↑ and Enter: this used
    # to pick the menu's last entry, quit
    # (each key once its effect shows, as a person sees it: on a busy machine the menu
    # came after ↑, the keys at fixed pauses)
    def menu(console: Console) -> bool:
        return console.command.complete_state is not None

    def recalled(console: Console) -> bool:
        return console.command.text == typed

    keys: list[tuple[str, float, Seen | None]] = [(":", 0.1, None)]
    keys += [(c, 0.02, None) for c in typed]
    said_when_done = {
        "params": "parameters read",
        "set max_speed 800": "max_speed = 800 (verified)",
    }

    def done(n: int) -> tuple[float, Seen | None]:
        """The pause after Enter and what to see first: the command's message said `n`
        times in all (a page is sent at once: a pause)."""
        if typed not in said_when_done:
            return 0.6, None
        text = said_when_done[typed]
        return 0.1, lambda console: list(console.session.messages).count(text) >= n

    first = 1 + (typed == "params")  # the console read them once at the start
    keys += [("\r", *done(first)), (":", 0.1, None), (TAB, 0.2, menu), (UP, 0.2, recalled)]
    keys += [("\r", *done(first + 1)), (CTRL_C, 0.0, None)]
    session, record, _ = run_console(tmp_path, keys)
    assert not session.host.connected
    lines = [p for _, p in sent(record)]
    if typed == "page button":
        assert lines.count("K") == 2, lines
    elif typed == "params":  # once at the start, then twice
        assert session.messages.count("parameters read") == 3, session.messages
    else:
        assert session.messages.count("max_speed = 800 (verified)") == 2, session.messages


def test_quit_with_unsaved_parameters_asks_once(tmp_path: Path) -> None:
    verified = said("max_speed = 800 (verified)")
    keys = [(":", 0.1, None), ("set max_speed 800\r", 0.1, verified), (":", 0.1, None)]
    keys += [("quit\r", 0.3, None)]
    keys += [("w", 0.3, None)]  # still driving (w: A, forward): the first quit only warned
    keys += [(":", 0.1, None), ("quit\r", 0.0, None)]
    session, record, _ = run_console(tmp_path, keys)
    warning = "not saved: max_speed 500 → 800 — :save keeps it; quit again to leave"
    assert any(m.startswith(warning) for m in session.messages), session.messages
    payloads = [p for _, p in sent(record)]
    assert "A" in payloads and payloads[-1] == "Z"


def test_caps_lock_q_drives_front_left_and_does_not_quit(tmp_path: Path) -> None:
    _, record, _ = run_console(tmp_path, [("Q", 0.3), (" ", 0.3), (CTRL_C, 0.0)])
    payloads = [p for _, p in sent(record)]
    assert payloads.count("H") == 1 and payloads[-1] == "Z"


@pytest.mark.skipif(sys.platform == "win32", reason="POSIX file modes")
def test_history_keeps_no_refused_line_and_is_the_user_s_own(
    tmp_path: Path, private_data_folder: Path
) -> None:
    """Issue 64.12: a refused 100 KB line was saved (mode 0644) and recalled next time.
    It comes as a terminal pastes it, bracketed: typed key by key, prompt_toolkit redraws
    the line at each of its 100,000 keys (31 s and 4.9 GB here)."""
    pasted = "\x1b[200~set max_speed " + "9" * 100_000 + "\x1b[201~"
    keys = [(":", 0.1), ("fly away\r", 0.3), (":", 0.1), (pasted, 0.3), ("\r", 0.5)]
    keys += [(":", 0.1), ("latch on\r", 0.3), (CTRL_C, 0.0)]
    session, _, _ = run_console(tmp_path, keys)
    assert session.failures == 2, session.messages
    path = private_data_folder / "appmode" / "history"
    history = path.read_text()
    assert "+latch on" in history
    assert "fly" not in history and "9999" not in history
    assert path.stat().st_mode & 0o777 == 0o600


def test_history_is_kept_across_sessions_without_quit(
    tmp_path: Path, private_data_folder: Path
) -> None:
    first = [(":", 0.1), ("latch on\r", 0.3), (":", 0.1), ("quit\r", 0.0)]
    run_console(tmp_path, first)
    history = (private_data_folder / "appmode" / "history").read_text()
    assert "+latch on" in history and "+quit" not in history
    recall = [(":", 0.5), (UP, 0.5), ("\r", 0.5), (CTRL_C, 0.0)]  # a person's pace
    session, _, _ = run_console(tmp_path, recall)
    assert session.messages.count("latched driving on") == 1  # recalled from the file
