"""A board's ports read together, with no I/O (docs/protocol.md §8–§12, §15).

UART2's grammar depends on the board's state: the drive type fixes the length of motor
frames and encoder reports, and system_mode bit 7 (APP mode) turns it into APP text. A
`PortsReader` follows that state from what the host sends (an APP `{8:…}` or a UART2
system_mode setting), from the moment it is sent, and decodes every direction.
"""

from __future__ import annotations

from appmode.protocol import app, app_decoders, chassis, control, control_decoders, params
from appmode.protocol.layouts import VELOCITY, Layout
from appmode.protocol.params import DriveType

SENT, RECEIVED, SENT2, RECEIVED2 = ">", "<", "2>", "2<"
SENT_CHASSIS, RECEIVED_CHASSIS = "c>", "c<"
"""A WHEELTEC board's chassis port (§15): velocity frames in, status frames out."""
SENT_DIRECTIONS = (SENT, SENT2, SENT_CHASSIS)
"""What a host sent, on any port."""
RECEIVED_DIRECTIONS = (RECEIVED, RECEIVED2, RECEIVED_CHASSIS)
"""What a board sent, on any port."""
Event = app.Event | control.HostEvent | control.BoardEvent | chassis.Event
APP_EVENTS = app.Event
"""The events of APP text: on UART2, what APP mode carries (§12)."""


class PortsReader:
    """Decoders for `>`, `<`, `2>` and `2<`, kept in step with the board's system_mode,
    and for the chassis port's `c>` and `c<`."""

    def __init__(
        self, system_mode: int = 0, drive: DriveType | None = None, layout: Layout = VELOCITY
    ) -> None:
        self.host = app_decoders.HostDecoder()
        self.board = layout.board_decoder()
        self.host2 = control_decoders.FrameDecoder()
        self.board2 = control_decoders.ReplyDecoder()
        self.chassis: dict[str, chassis.CommandDecoder | chassis.StatusDecoder] = {
            SENT_CHASSIS: chassis.CommandDecoder(),
            RECEIVED_CHASSIS: chassis.StatusDecoder(),
        }
        self.app_mode = False
        self.follow(system_mode if drive is None else system_mode & ~7 | int(drive))

    def follow(self, system_mode: int) -> list[tuple[str, Event]]:
        """Read UART2 as a board with this system_mode; what the UART2 decoders held."""
        on = bool(system_mode & params.MODE_BIT["app_mode"])
        held: list[tuple[str, Event]] = [(SENT2, e) for e in self.host2.set_app_mode(on)]
        held += [(RECEIVED2, e) for e in self.board2.set_app_mode(on)]
        drive = params.drive_type(system_mode) or DriveType.OMNI
        self.host2.drive = drive
        self.board2.wheels = control.motor_count(drive)
        self.app_mode = on
        return held

    def feed(self, direction: str, data: bytes) -> list[tuple[str, Event]]:
        """The events of `data` in `direction`, each with its direction (a mode change
        reports what a UART2 decoder held, as its own direction)."""
        if direction == RECEIVED:
            return [(RECEIVED, e) for e in self.board.feed(data)]
        if direction == RECEIVED2:
            return [(RECEIVED2, e) for e in self.board2.feed(data)]
        if direction in self.chassis:
            return [(direction, e) for e in self.chassis[direction].feed(data)]
        decoder = self.host if direction == SENT else self.host2
        out: list[tuple[str, Event]] = []
        for event in decoder.feed(data):
            out.append((direction, event))
            mode = control.system_mode_set(event)
            if mode is not None:
                out += self.follow(mode)
        return out

    def flush(self) -> list[tuple[str, Event]]:
        """What every decoder holds at the end."""
        out: list[tuple[str, Event]] = [(SENT, e) for e in self.host.flush()]
        out += [(RECEIVED, e) for e in self.board.flush()]
        out += [(SENT2, e) for e in self.host2.flush()]
        out += [(RECEIVED2, e) for e in self.board2.flush()]
        for direction, decoder in self.chassis.items():
            out += [(direction, e) for e in decoder.flush()]
        return out
