"""One driving session: the host, what is in force, and the console's commands.

Both faces of `appmode drive` use it: the full-screen console (keys and a command line)
and the script mode that reads the same commands line by line from stdin. It never
blocks: parameter reads and sets run as queries whose outcome arrives with `tick()`.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from typing import ClassVar

from appmode.errors import AppmodeError
from appmode.host.app.client import Host
from appmode.host.app.query import ParamQuery, QueryDone
from appmode.host.app.state import HostState
from appmode.host.app.tokens import parse_token
from appmode.host.events import BoardWarning, FarStop, LinkStatus
from appmode.host.link import LinkLost, Refused
from appmode.host.outcomes import QueryFailed
from appmode.host.waits import Wait
from appmode.ports.choice import BoardChoice
from appmode.protocol import param_values, params
from appmode.protocol.directions import (
    STOP_LETTER,
    Page,
    grid_for,
)
from appmode.protocol.layouts import VELOCITY
from appmode.protocol.twist import Twist
from appmode.session.app import status
from appmode.session.app.commands import COMMANDS, KEYS, KEYS_HELP
from appmode.session.app.velocity import letter_for, speed_and_drive
from appmode.session.base import BaseSession
from appmode.session.hold import HoldToDrive
from appmode.session.instruments import Instruments
from appmode.session.rows import (
    Row,
    hold_mode,
)

SPEED_CHANGE = 0.1
"""How far (a share of it) the speed a twist asks must be from max_speed for a new
`{0:N}` to be sent."""


class AppSession(BaseSession):
    """A session on the APP port: pages, letters and the nine parameters."""

    host: Host
    commands = COMMANDS
    keys_help = KEYS_HELP
    keys = KEYS
    aliases: ClassVar[dict[str, str]] = {"read": "params"}
    waveforms = True

    def __init__(
        self,
        choice: BoardChoice,
        driving: HoldToDrive | None = None,
        record: str | None = None,
        on_message: Callable[[str], None] | None = None,
    ) -> None:
        super().__init__(choice.target, driving, on_message)
        self.host = Host(choice.target, tap=self._tap, profile=choice.profile, confirm_stop=True)
        self.baseline: tuple[int, ...] | None = None
        """The parameters as first read, or as last sent to flash: what a quit would keep."""
        self._open_recording(record)

    # ------------------------------------------------------------ life cycle

    def start(self) -> None:
        """Put the board on the direction page (stopped) and read its parameters; the
        stop guard starts watching."""
        self.guard.start()
        self.switch_page("J")
        self.host.start_query(ParamQuery(where=self.url, specs=self.specs))

    def close(self) -> None:
        """Stop the car — `Z` is the last byte sent, confirmed on the board's A records —
        and close everything."""
        self.guard.close()
        try:
            self._close_link(self.host)
        finally:
            self._drop_recorder()
            self.closing_notes += self.host.notes

    # ------------------------------------------------------------ time

    def tick(self) -> bool:
        """Read what arrived, finish queries, and stop a held direction that timed out.

        Returns whether anything happened (a view needs redrawing)."""
        events = self.host.poll_nowait()
        for event in events:
            if isinstance(event, LinkStatus):
                self.say(event.text)
                if not event.up:
                    self.driving.stop()  # what the car was last told stays in force
            elif isinstance(event, BoardWarning):
                self.say(f"WARNING: {event.text}")
            elif isinstance(event, FarStop):
                self._far_stop(event)
            elif isinstance(event, QueryDone):
                if self.baseline is None:
                    self.baseline = event.values
                self.say(event.text)
            elif isinstance(event, QueryFailed):
                self.fail(event.text)
        if self.watch():  # first: a stop the guard sent is not sent again
            return True
        if self.driving.release_due(self.host.now()):
            self._send_letter(STOP_LETTER)
            return True
        return bool(events)

    # ------------------------------------------------------------ driving

    def press(self, letter: str) -> None:
        """A driving key: a letter of the current page, or Z."""
        if self.link_down():
            return
        to_send = self.driving.press(letter, self.host.now())
        if to_send is not None:
            self._send_letter(to_send)

    def grid_key(self, row: int, col: int) -> str:
        return grid_for(self.page)[row][col]

    def _move(self, twist: Twist) -> None:
        """The nearest direction to `twist` on its page, at the speed asked: max_speed
        is set (verified) when it is over SPEED_CHANGE from the speed asked."""
        speed, drive = speed_and_drive(self.host.state)
        letter = letter_for(twist, drive, self.host.profile.velocity_si)
        if letter is None:
            return
        if self.page_letter != letter.page and not self._send(letter.page.encode()):
            return
        self._ask_speed(letter.speed, speed)
        if self.in_force != letter.letter:
            self._send_letter(letter.letter)

    def _ask_speed(self, wanted: int, speed: int | None) -> None:
        """Set max_speed to `wanted` (within its range) unless it is near it already."""
        index = self.host.state.layout.speed_index
        if index is None or self.busy:
            return
        spec = self.specs[index]
        value = min(spec.maximum, max(spec.minimum, wanted))
        if value != wanted:
            self._say_once(f"a speed over {spec.name}'s range is driven at {value}")
        if speed is None or abs(value - speed) > SPEED_CHANGE * max(speed, 1):
            self.set_param(index, value)

    def stop(self) -> None:
        self.driving.stop()
        self._send_letter(STOP_LETTER)

    @property
    def in_force(self) -> str:
        """The drive letter the board was last sent and follows, or `Z`."""
        return status.in_force(self.host)

    @property
    def page_letter(self) -> str:
        return self.host.state.end.page_letter

    @property
    def page(self) -> Page:
        return status.page_of(self.host)

    @property
    def moving(self) -> bool:
        return self.host.state.end.moving

    def _guard_stop(self) -> None:
        self.host.send(self.host.state.end.stop)

    def _forget_motion(self) -> None:
        self.driving.stop()

    def _far_stop(self, stop: FarStop) -> None:
        """The car's host (a share) stopped the car, or could not: said, and forgotten."""
        if stop.stopped:
            self._forget_motion()
            self.say(f"the car's host stopped the car: {stop.text}")
        else:
            self.say(f"WARNING: the car's host could not stop the car: {stop.text}")

    def switch_page(self, letter: str) -> None:
        self.driving.stop()
        self._send(letter.encode())

    def _send_letter(self, letter: str) -> None:
        """Send a letter; a stop ends an open frame first (its `Z` would be swallowed)."""
        self._send(self.host.state.end.stop if letter == STOP_LETTER else letter.encode())

    def _send(self, data: bytes) -> bool:
        """Send; the host follows what left (the page, the letter in force)."""
        try:
            self.host.send(data)
        except (LinkLost, Refused) as exc:
            self.say(str(exc))
            self.driving.stop()
            return False
        return True

    @property
    def _speed_keys(self) -> Mapping[str, int]:
        return self.host.state.layout.profile.speed_keys

    # ------------------------------------------------------------ what it shows

    def status_rows(self) -> list[Row]:
        return status.app_rows(self.host, hold_mode(self.driving))

    @property
    def specs(self) -> param_values.Specs:
        """The parameters' table of the board's profile."""
        return self.host.state.layout.params

    def instruments(self) -> Instruments:
        return status.app_instruments(self.host, self.baseline)

    def grid_cells(self) -> list[list[str]]:
        return status.app_grid(self.host)

    def cell_names(self) -> list[list[str]]:
        return status.app_cell_names(self.host)

    def lit_cell(self) -> tuple[int, int] | None:
        return status.app_lit(self.host)

    def telemetry_state(self) -> HostState:
        return self.host.state

    # ------------------------------------------------------------ parameters

    def _query(self, query: ParamQuery) -> None:
        if self.host.state.query is not None:
            self.say("busy: a parameter read or set is in progress")
            return
        if self.in_force != STOP_LETTER:
            self._frame_while_driving()
        self.host.start_query(query)

    def _frame_while_driving(self) -> None:
        """A parameter frame is about to go out while a direction is in force: on the
        reference firmware every frame stops the car (§13), so say so, never silently."""
        if self.host.state.frames_stop:
            self.stop()
            self.say("stopped: a minibalance car stops at every frame; drive again after it")
        elif self.host.state.layout is VELOCITY:  # the sheet's board: what the other does
            self.say("note: on a minibalance car (--profile) this frame would stop it")

    def read_params(self) -> None:
        self._query(ParamQuery(where=self.url, specs=self.specs))

    def set_param(self, index: int, value: int) -> None:
        """Set a parameter to the frame's integer `value`, verified by reading back."""
        param_values.check(self.specs, index, value)
        self._query(ParamQuery((index, value), where=self.url, specs=self.specs))

    def parameters(self) -> dict[str, int | float]:
        current = self.host.state.params
        if current is None:
            return {}
        specs = self.specs
        return {
            s.name: param_values.user_number(s, v)
            for s, v in zip(specs, current.values, strict=True)
        }

    def set_parameter(self, name: str, value: str) -> None:
        index = param_values.lookup(self.specs, name)
        self.set_param(index, param_values.from_user(self.specs[index], value))

    def parameter_specs(self) -> param_values.Specs:
        return self.specs

    def _speed_index(self) -> int:
        index = self.host.state.layout.speed_index
        if index is None:
            name = self.host.state.layout.profile.name
            raise AppmodeError(f"the {name} profile has no speed parameter: + and - change nothing")
        return index

    def change_speed(self, delta: int) -> None:
        keys = self._speed_keys
        if self.host.state.layout.speed_index is None and keys:
            self._speed_key(delta, keys)
            return
        index = self._speed_index()
        current = self.host.state.params
        if current is None:
            self.say("parameters not read yet: reading them, try again")
            self.read_params()
            return
        spec = self.specs[index]
        wanted = current.values[index] + delta
        value = min(spec.maximum, max(spec.minimum, wanted))
        if value != wanted:
            self.say(
                f"{spec.name} {wanted} is out of {spec.minimum}–{spec.maximum}: setting {value}"
            )
        self.set_param(index, value)

    def _speed_key(self, delta: int, keys: Mapping[str, int]) -> None:
        """Send the firmware's own speed letter for a change of `delta` (`X`: +100)."""
        letter = next((k for k, step in keys.items() if (step > 0) == (delta > 0)), None)
        if letter is None or delta == 0:
            raise AppmodeError(f"this firmware's speed letters ({', '.join(keys)}) go one way")
        if self._send(letter.encode()):
            self.say(f"sent {letter}: this firmware's speed {keys[letter]:+d}")

    def save(self) -> None:
        if self._send(b"{Q:W}"):
            current = self.host.state.params
            if current is not None:
                self.baseline = current.values
            self.say("sent {Q:W}: the board saves its parameters to flash (it sends no reply)")

    def unsaved_warning(self) -> str | None:
        """What was set in this session and not sent to flash since, in a line; None if
        nothing was."""
        current = self.host.state.params
        if current is None or self.baseline is None:
            return None
        changed = [
            f"{p.name} {param_values.to_user(p, a)} → {param_values.to_user(p, b)}"
            for p, a, b in zip(self.specs, self.baseline, current.values, strict=False)
            if a != b
        ]
        return f"not saved: {', '.join(changed)}" if changed else None

    def speed_command(self, args: list[str]) -> None:
        """`speed +N`, `speed -N` or `speed N`: max_speed (the profile's speed parameter)."""
        number = params.whole(args[0].lstrip("+-")) if len(args) == 1 else None
        if number is None:
            raise AppmodeError("usage: speed +N, speed -N or speed N")
        if args[0][0] in "+-":
            self.change_speed(-number if args[0][0] == "-" else number)
        else:
            self.set_param(self._speed_index(), number)

    def send_tokens(self, tokens: list[str]) -> None:
        """`send`: letters, frames and escaped bytes, as they are."""
        if not tokens:
            raise AppmodeError("usage: send TOKEN..., e.g. send J A or send {Q:P}")
        steps = [parse_token(token) for token in tokens]
        if any(isinstance(step, Wait) for step in steps):
            raise AppmodeError("send takes no waits here: use the wait command")
        self.driving.stop()
        for step in steps:
            assert isinstance(step, bytes)
            self._send(step)
        self.say(f"sent {' '.join(tokens)}")
