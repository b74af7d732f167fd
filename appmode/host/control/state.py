"""The control-port host as a state machine, with no I/O: what it knows of the board.

`ControlState.feed(data, now)` decodes the board's bytes (replies, encoder reports, APP
records in APP mode) and keeps the last report, the values read and the link counters;
`sent(data, now)` follows what the host sent, decoded as the board does: the frame in
force, the drive type and APP mode a system_mode set selects, and when the host's bytes
took the motion over (§8.3). A running ReadQuery is fed here and wants bytes sent
through the outbox. A view (the console) reads it all.
"""

from __future__ import annotations

import re
from collections import Counter, deque
from dataclasses import dataclass

from appmode.host.control.query import ControlOutcome, ReadDone, ReadQuery
from appmode.host.outcomes import QueryFailed
from appmode.host.stats import LinkStats
from appmode.protocol import app, control, control_decoders, params
from appmode.protocol.params import DriveType
from appmode.protocol.session_end import SessionEnd

OWED_FOR = 2.0
"""Seconds a read sent is taken to be still owed a reply; after that it was lost (a
board answers in milliseconds, a loaded host reads it within a second)."""
TAKEOVER_BYTE = 10
"""The board follows the control port from this byte on (the sheet; §13's is the 11th)."""

APP_QUIET = 1.0
"""Seconds without an APP record on UART2, in APP mode, after which the board has left
it (a reset, or system_mode set from the APP port: bit 7 is never saved, §12); the
board streams one every 50–80 ms while it is on."""
APP_RECORD = re.compile(rb"\{[ABC]-?\d+(?::-?\d+)*\}")
"""An APP record whole in bytes that no binary reply or report holds: the board speaks
APP text on UART2 (§12)."""
APP_MODE_BIT = params.MODE_BIT["app_mode"]

MOTION = (control.VelocityFrame, control.MotorFrame, control.PositionFrame)


@dataclass(frozen=True, slots=True)
class PortMode:
    """What the board's output showed of UART2's mode: APP text (`app`), or that it
    stopped (the board left APP mode: read system_mode anew)."""

    app: bool
    text: str


Received = control.BoardEvent | ControlOutcome | PortMode
Sent = control.HostEvent | app.HostEvent


class ControlState:
    """Last report and values seen, the frame in force and link counters."""

    def __init__(self, drive: DriveType | None = None, takeover_byte: int = TAKEOVER_BYTE) -> None:
        self.drive = drive
        """The board's drive type: told, or learnt from a system_mode read or sent."""
        self.takeover_byte = takeover_byte
        self.decoder = control_decoders.ReplyDecoder(None)
        self.sent_decoder = control_decoders.FrameDecoder(drive or DriveType.OMNI)
        """What was sent, decoded as the board does: is a frame left open?"""
        self.stats = LinkStats()
        self.report: control.EncoderReport | None = None
        self.report_at: float | None = None
        self.values: dict[str, int] = {}
        """Every value read so far (agreed replies), by name."""
        self.in_force: control.VelocityFrame | control.MotorFrame | control.PositionFrame | None
        self.in_force = None
        self.took_over_at: float | None = None
        """When this host's bytes made the control port drive the car."""
        self.query: ReadQuery | None = None
        self._outbox = bytearray()
        self._errors_at_start = 0
        self._queries = 0  # queries started
        self._owed: deque[tuple[float, int, int]] = deque()
        """Reads sent and not yet answered, in the order sent: (when, reply id, the
        query's number). The board answers them in that order, so a reply answers the
        oldest read of its id, and the reads sent before that one are lost (noise). A
        reply owed to an earlier query (a round of it that ended at its time-out on a
        loaded host, its replies late) is not the running one's: before, it answered
        the next query (`800` read after `defaults` had made it 500)."""
        self._owing: Counter[int] = Counter()
        """How many reads in `_owed` each reply id has."""
        self.app_end = SessionEnd()
        """What was sent in APP mode (§12): the drive letter the board follows there."""
        self.app_maybe = False
        """APP mode may be on: this host set bit 7, or the board sent APP records here;
        until a binary reply or report shows the port speaks frames. The stop then ends
        with `Z` too (the zero frame alone stops an APP-mode port only outside a frame)."""
        self._app_heard_at = 0.0
        """When the last APP record came in APP mode (or APP mode began)."""

    @property
    def app_mode(self) -> bool:
        """system_mode bit 7 as this host last set it, or as the board's APP records on
        UART2 show it: the port speaks the APP protocol (§12)."""
        return self.sent_decoder.app_mode

    @property
    def letter(self) -> str | None:
        """The APP drive letter sent here in APP mode that the board still follows."""
        return self.app_end.letter if self.app_end.moving else None

    # ------------------------------------------------------------ bytes

    def feed(self, data: bytes, now: float) -> list[Received]:
        """Decode board bytes; returns the events and the outcome of a query they end."""
        self.stats.bytes_in += len(data)
        return self._apply(self.decoder.feed(data), now)

    def sent(self, data: bytes, now: float) -> tuple[list[Sent], list[Received]]:
        """Follow bytes the host sent: (their events, board bytes read anew when a
        system_mode set switched APP mode)."""
        before = self.stats.bytes_out
        self.stats.bytes_out += len(data)
        if before < self.takeover_byte <= self.stats.bytes_out and self.took_over_at is None:
            self.took_over_at = now
        events = self.sent_decoder.feed(data)
        reread: list[Received] = []
        for event in events:
            if isinstance(event, app.HostEvent):
                self.app_end.sent(event.raw)
            elif event.raw == control.STOP:  # its last byte stops an APP-mode port too
                self.app_end.sent(app.encode(app.Stop()))
            if isinstance(event, control.ReadFrame):
                self._expire(now)  # a board that never answers: bounded all the same
                self._owed.append((now, event.read.reply_id, self._queries))
                self._owing[event.read.reply_id] += 1
            if isinstance(
                event, (control.VelocityFrame, control.MotorFrame, control.PositionFrame)
            ):
                self.in_force = None if event.raw == control.STOP else event
            mode = control.system_mode_set(event)
            if mode is not None:
                reread += self._follow_mode(mode, now)
        return events, reread

    def _follow_mode(self, mode: int, now: float) -> list[Received]:
        """A system_mode the host set: the drive type fixes frame lengths and the
        encoding of velocity, bit 7 moves the APP protocol onto this port (§12)."""
        self.learn_drive(mode)
        return self._switch(bool(mode & APP_MODE_BIT), now)

    def _switch(self, on: bool, now: float) -> list[Received]:
        """Decode both ways as APP text (`on`) or frames; what the board's decoder held."""
        if on:
            self.app_maybe, self._app_heard_at = True, now
        self.sent_decoder.set_app_mode(on)
        return self._apply(self.decoder.set_app_mode(on), now)

    def learn_drive(self, mode: int) -> None:
        """Take the drive type from a system_mode (read or sent), if it names one."""
        drive = params.drive_type(mode)
        if drive is not None:
            self.drive = drive
            self.sent_decoder.drive = drive

    def forget_drive(self) -> None:
        """system_mode may have changed on the board (load, defaults): read it anew."""
        self.drive = None

    def reset_decoder(self) -> None:
        """Forget a partial reply or report (after the link was lost)."""
        self.decoder = control_decoders.ReplyDecoder(None, self.decoder.app_mode)

    def _apply(self, events: list[control.BoardEvent], now: float) -> list[Received]:
        out: list[Received] = []
        for event in events:
            out.append(event)
            if isinstance(event, (*control.ERRORS, *app.ERRORS)):
                self.stats.count_error(now, len(event.raw))
                if not self.app_mode and APP_RECORD.search(event.raw):
                    out += self._app_text_seen(now)
                continue
            self.stats.count_record(now)
            if isinstance(event, app.RECORDS):
                self._app_heard_at = now
                outcome = self._app_mode_set()
                if outcome is not None:
                    out.append(outcome)
            elif isinstance(event, (control.Reply, control.EncoderReport)):
                self.app_maybe = False  # the port speaks frames
            if isinstance(event, control.EncoderReport):
                self.report, self.report_at = event, now
            elif isinstance(event, control.Reply) and self._answers_this_query(event, now):
                assert self.query is not None
                outcome = self._step(*self.query.on_reply(event, now))
                if outcome is not None:
                    out.append(outcome)
        return out

    def _app_text_seen(self, now: float) -> list[Received]:
        """The board sends APP records on UART2: APP mode is on (set from the APP port,
        or before this session): decode both ways as APP text from now on."""
        said = PortMode(
            True,
            "the board sends APP records on UART2: APP mode (system_mode bit 7) is on; "
            "drive letters work here, frames do not",
        )
        return [said, *self._switch(True, now)]

    def _app_mode_set(self) -> ControlOutcome | None:
        """A set of system_mode that turns APP mode on is verified by the board's APP
        records on UART2 (no binary read is answered in APP mode, §12)."""
        query = self.query
        frame = None if query is None else query.set_frame
        if frame is None or control.system_mode_set(frame) is None:
            return None
        if not frame.value & APP_MODE_BIT:
            return None
        self.query = None
        self.values["system_mode"] = frame.value
        return ReadDone(
            {"system_mode": frame.value},
            f"set system_mode = {frame.value} (APP mode on: the board's APP records now "
            "come on UART2; frames do not work until bit 7 is cleared with a {8:…} frame)",
        )

    def _answers_this_query(self, reply: control.Reply, now: float) -> bool:
        """Whether a reply answers a read of the running query: the oldest read of its
        id still owed one (one not sent here is taken as the running query's). The
        reads sent before that one were lost, whatever their id; reads sent OWED_FOR
        ago too (a board that answers none). A reply lost to noise costs the next query
        at most a reply, and only until a reply to a later read comes."""
        self._expire(now)
        answered = self._queries
        if self._owing[reply.id]:
            while True:
                _, reply_id, query = self._owed.popleft()
                self._owing[reply_id] -= 1
                if reply_id == reply.id:
                    answered = query
                    break
        return self.query is not None and answered == self._queries

    def _expire(self, now: float) -> None:
        """Forget the reads sent over OWED_FOR ago: their replies were lost."""
        while self._owed and self._owed[0][0] < now - OWED_FOR:
            _, reply_id, _ = self._owed.popleft()
            self._owing[reply_id] -= 1

    # ------------------------------------------------------------ queries

    def start_query(self, query: ReadQuery, now: float) -> None:
        """Begin a read or set; its bytes wait in the outbox."""
        self.query = query
        self._errors_at_start = self.stats.errors
        self._queries += 1
        self._outbox += query.start(now)

    def tick(self, now: float) -> ControlOutcome | PortMode | None:
        """Let time pass: a query may send its next round (into the outbox) or fail; an
        APP-mode port that fell silent has left APP mode."""
        if self.app_mode and now - self._app_heard_at > APP_QUIET:
            self._switch(False, now)
            return PortMode(
                False,
                f"no APP record on UART2 for {APP_QUIET:g} s: the board left APP mode (a "
                "reset, or system_mode set from the APP port); reading system_mode",
            )
        if self.query is None:
            return None
        return self._step(*self.query.on_time(now))

    def take_outbox(self) -> bytes:
        """Bytes the state wants sent."""
        data = bytes(self._outbox)
        self._outbox.clear()
        return data

    def _step(self, data: bytes, outcome: ControlOutcome | None) -> ControlOutcome | None:
        self._outbox += data
        if outcome is None:
            return None
        self.query = None
        if isinstance(outcome, ReadDone):
            self.values.update(outcome.values)
            if "system_mode" in outcome.values:
                self.learn_drive(outcome.values["system_mode"])
        elif isinstance(outcome, QueryFailed) and self.stats.errors > self._errors_at_start:
            garbled = self.stats.errors - self._errors_at_start
            outcome = QueryFailed(
                f"{outcome.text} ({garbled} garbled replies or bytes came meanwhile: "
                "the link is noisy)"
            )
        return outcome
