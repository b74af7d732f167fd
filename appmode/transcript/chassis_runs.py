"""Transcripts with a chassis port's lines (`c>`, `c<`) run against a board: its status
frames decoded for the matcher on virtual time (`feed_virtual`), and a run in real time
against any chassis port (`run_live_chassis`)."""

from __future__ import annotations

import contextlib
import time
from collections.abc import Callable

import serial

from appmode.errors import AppmodeError
from appmode.line.wire import CHASSIS, CHASSIS_BAUD, Wire
from appmode.ports.target import Target
from appmode.ports.urls import open_link
from appmode.protocol import chassis
from appmode.protocol.transcript import Transcript
from appmode.transcript.matcher import Check

STEP = 0.005
"""Seconds between looks at a live chassis port: its frames come every 50 ms."""


def feed_virtual(check: Check, decoder: chassis.StatusDecoder, wire: Wire, now: float) -> None:
    """The chassis port's frames delivered by `now`, each at the time its last byte came."""
    for when, data in wire.pump_timed(now, CHASSIS):
        for event in decoder.feed(data):
            check.on_record(event, when, CHASSIS)


def run_live_chassis(
    transcript: Transcript,
    url: Target,
    progress: Callable[[str], None] | None = None,
) -> tuple[Check, float]:
    """Run `transcript` in real time against the chassis port at `url` (a sim:// URL: a
    board booted as it opens, its time 0 its power-up); the check and the time reached."""
    check = Check(transcript)
    try:
        link = open_link(url, timeout=0, baud=CHASSIS_BAUD)
    except AppmodeError as exc:
        check.failure = f"{transcript.path}: {exc}"
        return check, 0.0
    origin = time.monotonic()
    decoder = chassis.StatusDecoder()
    shown = -1
    now = 0.0
    try:
        while not check.done:
            now = time.monotonic() - origin
            for _, data in check.due(now):
                link.write(data)
            waiting = link.in_waiting
            data = link.read(waiting) if waiting else b""
            for event in decoder.feed(data):
                check.on_record(event, time.monotonic() - origin, CHASSIS)
            check.on_time(time.monotonic() - origin)
            if progress is not None and int(now * 2) != shown:
                shown = int(now * 2)
                progress(f"{transcript.path}: {now:5.1f} / {check.end:.1f} s")
            due = check.next_time()
            time.sleep(STEP if due is None else max(0.0, min(STEP, due - now)))
    except (serial.SerialException, OSError) as exc:
        check.failure = f"{transcript.path}: at {now:.3f} s: chassis link lost: {exc}"
    finally:
        with contextlib.suppress(serial.SerialException, OSError):
            link.write(chassis.STOP)  # the car is never left moving
        link.close()
    return check, time.monotonic() - origin
