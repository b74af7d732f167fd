"""The board's APP port (§2–§5, §13): letters steer, frames read, set and save the nine
parameters. It reads UART3, and UART2 while APP mode is on (§12), each with its own
decoder: the sheet's checked grammar, or the reference firmware's byte-by-byte intake."""

from __future__ import annotations

import math

from appmode.board.chip import c_int
from appmode.board.core import UART2, UART3, Core
from appmode.board.intake import INT_PARAMS, FirmwareIntake, Frame
from appmode.board.telemetry import Telemetry
from appmode.protocol import app, app_decoders, params
from appmode.protocol.directions import PAGE_LETTERS, Page, motion_for
from appmode.protocol.escaping import escape


class AppPort:
    """What the board makes of APP bytes, on either port."""

    def __init__(self, core: Core, telemetry: Telemetry) -> None:
        self.core = core
        self.telemetry = telemetry
        profile = core.profile
        self._firmware = profile.firmware_frames
        self._decoders = {UART3: app_decoders.HostDecoder(), UART2: app_decoders.HostDecoder()}
        self._intakes = {
            port: FirmwareIntake(profile.steer_in_frames, profile.frame_restarts)
            for port in (UART3, UART2)
        }

    def receive(self, data: bytes, now: float, port: str) -> None:
        """Apply APP bytes that arrived on `port` at `now`."""
        if self._firmware:
            for item in self._intakes[port].feed(data):
                if isinstance(item, Frame):
                    self._apply_frame(item, now, port)
                else:
                    self._apply(item.event, now, port, framed=item.framed)
        else:
            for event in self._decoders[port].feed(data):
                self._apply(event, now, port)

    def _apply(self, event: app.HostEvent, now: float, port: str, framed: bool = False) -> None:
        core = self.core
        shown = escape(event.raw)
        keys = core.profile.file.speed_keys if core.profile.file is not None else {}
        letter = event.raw.decode("latin-1")
        if not framed and letter in keys:  # a data profile's speed key
            core.speed_change += keys[letter]
            core.note(now, "applied", f"{shown}: speed {core.max_speed:g}", port)
            return
        if isinstance(event, (app.Move, app.Stop, app.SwitchPage, app.Noise)):
            if isinstance(event, app.Noise):
                core.errors += not framed
            if port == UART3 and core.uart2_control:
                if not framed:
                    core.note(now, "rejected", f"{shown}: ignored: UART2 drives (§8.3)", port)
                return
            before = (core.direction, core.turn, core.page)
            did = self._steer(event)
            if isinstance(event, app.Noise):
                did = f"unrecognised byte, {did}"
            if not framed:
                level = "rejected" if isinstance(event, app.Noise) else "applied"
                core.note(now, level, f"{shown}: {did}", port)
            elif before != (core.direction, core.turn, core.page):
                core.note(now, "applied", f"{shown} in a frame: {did} (§13)", port)
        elif isinstance(event, app.BadFrame):
            core.errors += 1
            core.note(now, "rejected", f"{shown}: {event.reason}", port)
        elif isinstance(event, app.SetParam):
            core.params[event.index] = event.value
            core.note(now, "applied", f"{shown}: {event.name} = {event.value}", port)
        else:
            if event.warning is not None:
                core.warnings += 1
                core.note(now, "warning", f"{shown}: {event.warning}", port)
            if isinstance(event, app.ReadParams):
                self.telemetry.request_c(now, shown, port)
            else:
                core.save(now, shown, port)

    def _apply_frame(self, frame: Frame, now: float, port: str) -> None:
        core = self.core
        shown = escape(frame.raw)
        if frame.action == "read":
            self.telemetry.request_c(now, shown, port)
        elif frame.action == "save":
            core.save(now, shown, port)
        elif frame.action == "ignored" or frame.index not in core.profile.settable:
            reason = frame.reason or f"parameter {frame.index} is not settable on this board"
            core.note(now, "rejected", f"{shown}: ignored: {reason}", port)
        else:
            index, file = frame.index, core.profile.file
            whole = file is not None or index in INT_PARAMS  # a data profile's: integers
            kept = c_int(frame.value) if whole else frame.value
            core.params[index] = kept
            name = (file.params if file is not None else params.PARAMS)[index].name
            core.note(now, "applied", f"{shown}: {name} = {kept:.10g}", port)

    def _steer(self, event: app.ByteEvent) -> str:
        """Apply one byte's direction logic (§2.1, §4; §13's rotation rule); what it did."""
        core = self.core
        profile = core.profile
        sticky = profile.sticky_rotation
        if isinstance(event, app.SwitchPage):
            core.page = PAGE_LETTERS[event.letter]
            core.direction = 0
            if core.page is Page.BUTTON:
                core.turn = 0
            return f"stop, {core.page.value} page"
        if isinstance(event, app.Move) and (
            core.page is Page.DIRECTION or not event.numeric or profile.numeric_buttons
        ):
            motion = motion_for(core.page, event.direction, profile.buttons)
            if motion is None:
                core.direction = 0
                core.turn = 0
                return f"stop ({event.letter} is no button here)"
            x, y, z = motion.holonomic
            if sticky and core.page is Page.BUTTON and z and not (x or y):
                core.direction, core.turn = 0, int(math.copysign(1, z))
            else:
                core.direction, core.turn = event.direction, 0
            return f"{motion.name} ({core.page.value} page)"
        core.direction = 0
        if core.page is Page.BUTTON or not sticky:
            core.turn = 0
        return "stop" if not core.turn else "stop; the rotation goes on (§13)"
