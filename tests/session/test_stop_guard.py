"""The stop authority's guard (issue 49.2): a session whose ticks stall while the car
moves gets its stop from the guard's thread, on the board's own recording."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import pytest

from appmode.session.authority import (
    LAPSE,
    STALL,
    STARVED,
    TASKS,
    StopGuard,
    runnable,
    thread_times,
)
from appmode.session.hold import HoldToDrive
from appmode.transcript.reading import read_transcript
from tests.support.sessions import session as open_board


def test_the_guard_stops_a_moving_session_whose_ticks_stall() -> None:
    stops: list[float] = []
    guard = StopGuard(lambda: True, lambda: stops.append(time.monotonic()))
    guard.start()
    try:
        started = time.monotonic()
        for _ in range(10):  # ticks keep it from acting
            guard.beat()
            time.sleep(STALL / 5)
        assert not stops
        time.sleep(STALL * 6)  # no tick: the view is blocked
        assert len(stops) == 1, "once, until the session acknowledges it"
        assert stops[0] - started >= 10 * STALL / 5
        assert guard.beat() is True and guard.beat() is False
    finally:
        guard.close()


def test_the_guard_leaves_a_stopped_car_alone() -> None:
    stops: list[float] = []
    guard = StopGuard(lambda: False, lambda: stops.append(time.monotonic()))
    guard.start()
    time.sleep(STALL * 4)
    guard.close()
    assert not stops


def test_a_latched_session_that_stops_ticking_is_stopped(tmp_path: Path) -> None:
    record = tmp_path / "s.transcript"
    session = open_board("sim://", HoldToDrive(latched=True), record=str(record))
    try:
        session.start()
        ticked = time.monotonic()
        session.tick()
        session.run("drive A")
        driven = time.monotonic()
        assert session.moving
        time.sleep(STALL * 6)  # the session's loop is "blocked": no tick
        session.tick()
        assert not session.moving
        assert any("without a tick while driving" in m for m in session.messages)
    finally:
        session.close()
    sent = [e for e in read_transcript(record).entries if e.direction == ">"]
    drive = next(i for i, e in enumerate(sent) if e.data == b"A")
    stop = sent[drive + 1]
    assert stop.data == b"Z"
    # STALL counts from the last tick, which came before the A by up to `driven - ticked`
    assert STALL - (driven - ticked) <= stop.time - sent[drive].time < STALL * 4


def test_after_a_signal_not_acted_on_the_guard_stops_the_car_and_ends_the_process(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """Deliver 2: a signal ends the session within a second, whatever is blocked."""
    from appmode.session import authority

    signalled = time.monotonic()
    ended: list[tuple[float, int]] = []
    stops: list[float] = []
    monkeypatch.setattr(authority.signals, "ending_since", lambda: signalled)
    monkeypatch.setattr(
        authority.os, "_exit", lambda status: ended.append((time.monotonic(), status))
    )
    guard = StopGuard(lambda: True, lambda: stops.append(time.monotonic()))
    guard.start()
    deadline = time.monotonic() + 5
    while not ended and time.monotonic() < deadline:
        guard.beat()  # the ticks go on: only the signal is not acted on
        time.sleep(0.01)
    guard.close()
    assert ended and ended[0][1] == 130
    assert authority.GRACE <= ended[0][0] - signalled < 1.0 + 0.5  # a loaded machine's margin
    assert stops and stops[0] <= ended[0][0]


TICKING = """
import sys, time
from appmode.session.authority import StopGuard
guard = StopGuard(lambda: True, lambda: print("stop", flush=True))
guard.start()
print("ticking", flush=True)
end = time.monotonic() + float(sys.argv[1])
while time.monotonic() < end:
    guard.beat()  # the session ticks every 10 ms, whenever it runs
    time.sleep(0.01)
guard.close()
print("done", flush=True)
"""


@pytest.mark.skipif(not hasattr(signal, "SIGSTOP"), reason="needs SIGSTOP (POSIX)")
def test_time_the_whole_process_was_not_running_does_not_count_as_a_stall() -> None:
    """A loaded machine that does not schedule the process (here: SIGSTOP) stalls the
    session and its guard alike: the guard judges the ticks over the time it ran, so
    it does not stop a session that ticks whenever it runs."""
    process = subprocess.Popen(
        [sys.executable, "-c", TICKING, "2.5"], stdout=subprocess.PIPE, text=True
    )
    assert process.stdout is not None
    try:
        assert process.stdout.readline() == "ticking\n"
        for _ in range(3):
            time.sleep(0.3)
            process.send_signal(signal.SIGSTOP)
            time.sleep(STALL * 3)  # neither the session nor its guard runs
            process.send_signal(signal.SIGCONT)
        out, _ = process.communicate(timeout=30)
    finally:
        process.kill()
    assert out == "done\n"


def test_time_the_session_s_thread_waited_for_a_cpu_counts_only_up_to_starved(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """A busy machine that runs the guard but keeps the session's thread waiting for a
    CPU (Linux's schedstat says so: found beside a second suite, a script's thread 0.45
    s in the run queue of 0.48) does not make the guard stop a session that would tick;
    it stops the car once the session has gone STARVED seconds without a tick."""
    from appmode.session import authority

    started = time.monotonic()
    monkeypatch.setattr(authority, "thread_times", lambda _: (0.0, time.monotonic() - started))
    monkeypatch.setattr(authority, "runnable", lambda _: True)
    stops: list[float] = []
    guard = StopGuard(lambda: True, lambda: stops.append(time.monotonic()))
    guard.start()
    try:
        deadline = time.monotonic() + STARVED + 2
        while not stops and time.monotonic() < deadline:
            time.sleep(0.01)
    finally:
        guard.close()
    assert stops, "a session starved for good is stopped"
    assert STARVED <= stops[0] - started < STARVED + 1.0  # a loaded machine's margin


def test_the_guard_acts_on_a_source_gone_quiet_even_while_the_session_ticks() -> None:
    stops: list[float] = []
    guard = StopGuard(lambda: True, lambda: stops.append(time.monotonic()), lambda: "quiet")
    guard.start()
    try:
        deadline = time.monotonic() + 2
        while not stops and time.monotonic() < deadline:
            guard.beat()
            time.sleep(0.01)
    finally:
        guard.close()
    assert len(stops) == 1 and guard.why == "quiet"


def test_a_key_let_go_stops_the_car_though_the_session_waits_for_a_cpu(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The guard does not count a session's wait for a CPU as a stall (up to STARVED),
    but a held key's repeats that stopped coming end the motion by their own clock: a
    session starved beside a second suite drove on 0.62 s after the key was let go."""
    from appmode.session import authority

    started = time.monotonic()
    monkeypatch.setattr(authority, "thread_times", lambda _: (0.0, time.monotonic() - started))
    monkeypatch.setattr(authority, "runnable", lambda _: True)
    record = tmp_path / "s.transcript"
    session = open_board("sim://", HoldToDrive(first_timeout=0.3), record=str(record))
    try:
        session.start()
        session.tick()
        session.press("A")
        session.tick()  # the last tick: the session "waits for a CPU" from here
        time.sleep(STARVED + 0.5)
        session.tick()
        assert not session.moving
        assert not any("without a tick" in m for m in session.messages)  # a key let go
    finally:
        session.close()
    sent = [e for e in read_transcript(record).entries if e.direction == ">"]
    drive = next(i for i, e in enumerate(sent) if e.data == b"A")
    stops = [e.time - sent[drive].time for e in sent[drive + 1 :] if e.data == b"Z"]
    assert len(stops) == 2, stops  # the guard's, and closing's: the tick sent no other
    assert 0.3 + LAPSE <= stops[0] < STARVED - 0.1, stops  # by the key's clock, not STARVED


@pytest.mark.skipif(not TASKS.is_dir(), reason="needs Linux's /proc/self/task")
def test_the_threads_times_and_state_are_read_from_the_system() -> None:
    me = threading.get_native_id()
    first = thread_times(me)
    end = time.thread_time() + 0.05
    while time.thread_time() < end:  # work
        pass
    later = thread_times(me)
    assert first is not None and later is not None
    assert later[0] - first[0] >= 0.04 and later[1] >= first[1] >= 0.0
    assert runnable(me)  # running, this very moment
    sleeper_id: list[int] = []
    wake = threading.Event()
    sleeper = threading.Thread(
        target=lambda: (sleeper_id.append(threading.get_native_id()), wake.wait(5))
    )
    sleeper.start()
    try:
        time.sleep(0.2)
        assert not runnable(sleeper_id[0])  # blocked: its wait counts towards STALL
    finally:
        wake.set()
        sleeper.join()
    assert thread_times(-1) is None and not runnable(-1)  # no such thread


@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="needs FIFOs")
def test_the_wait_for_a_recording_s_reader_counts_from_the_ending_signal(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A recording to a FIFO nobody opened waits CLOSE_WAIT for a reader at the end;
    after an ending signal, only what is left of it since the signal: a machine that
    acted on the signal late (here 0.4 s) does not end later still."""
    from appmode.host import signals
    from appmode.writer import CLOSE_WAIT

    fifo = tmp_path / "rec"
    os.mkfifo(fifo)
    session = open_board("sim://", HoldToDrive(latched=True), record=str(fifo))
    session.start()
    monkeypatch.setattr(signals._ending, "since", time.monotonic() - 0.45)
    closing = time.monotonic()
    session.close()
    took = time.monotonic() - closing
    assert took < signals.LAST_WAIT + 0.25, took  # 0.05 s left of it: LAST_WAIT, and a margin
    assert session.recording_failure is not None
    assert "no program opened it to read" in session.recording_failure
    assert signals.left(CLOSE_WAIT) == signals.LAST_WAIT
    monkeypatch.setattr(signals._ending, "since", None)
    assert signals.left(CLOSE_WAIT) == CLOSE_WAIT
