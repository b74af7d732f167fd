"""One driving session: the host, what is in force, and the console's commands.

Both faces of `appmode drive` use it: the full-screen console (keys and a command line)
and the script mode that reads the same commands line by line from stdin. It never
blocks: parameter reads and sets run as queries whose outcome arrives with `tick()`.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from typing import ClassVar

from appmode.errors import AppmodeError
from appmode.host.client import Host
from appmode.host.link import LinkLost
from appmode.host.query import ParamQuery, QueryDone, QueryFailed
from appmode.host.state import BoardWarning, HostState, LinkStatus
from appmode.host.tokens import Wait, parse_token
from appmode.ports.target import Target
from appmode.protocol import param_values, params
from appmode.protocol.directions import (
    PAGE_LETTERS,
    PAGE_NAMES,
    STOP_LETTER,
    Page,
    grid_for,
    letter_name,
)
from appmode.protocol.layouts import VELOCITY, Layout, named
from appmode.session import instruments
from appmode.session.app_commands import COMMANDS
from appmode.session.base import BaseSession
from appmode.session.commands import SPEED_KEYS
from appmode.session.hold import HoldToDrive
from appmode.session.instruments import Instruments, Value
from appmode.session.status import (
    GLYPHS,
    Row,
    Span,
    hold_mode,
    link_rows,
    telemetry,
    unsent_row,
)

KEYS_HELP = (
    "arrows, q w e / a s d / z x c drive · space stop · i j k page · l latch\n"
    "+ - speed · p params · v waveforms · : command · ? help · Ctrl-Q quit"
)
"""The console's keys, as its panel and help show them."""


class Session(BaseSession):
    """A session on the APP port: pages, letters and the nine parameters."""

    host: Host
    commands = COMMANDS
    keys_help = KEYS_HELP
    keys: ClassVar[dict[str, str]] = {
        "i": "page gravity",
        "j": "page joystick",
        "k": "page button",
        "p": "params",
        **SPEED_KEYS,
    }
    aliases: ClassVar[dict[str, str]] = {"read": "params"}
    waveforms = True

    def __init__(
        self,
        url: Target | str,
        driving: HoldToDrive | None = None,
        record: str | None = None,
        on_message: Callable[[str], None] | None = None,
        layout: Layout | None = None,
        stop_again: bytes | None = None,
        frames_stop: bool = False,
    ) -> None:
        """`layout`: how the board's records read (default: its sim:// URL's profile's,
        else the sheet's)."""
        super().__init__(url, driving, on_message)
        self.host = Host(
            self.target,
            tap=self._tap,
            layout=layout or named(self.target.profile or "sheet"),
            confirm_stop=stop_again is not None,
            stop_again=stop_again or b"",
            frames_stop=frames_stop,
        )
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
        """Stop the car — `Z` is the last byte sent, and with `stop_again` confirmed on
        the board's A records — and close everything."""
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

    def stop(self) -> None:
        self.driving.stop()
        self._send_letter(STOP_LETTER)

    @property
    def in_force(self) -> str:
        """The drive letter the board was last sent and follows, or `Z`."""
        return self.host.state.end.letter or STOP_LETTER

    @property
    def page_letter(self) -> str:
        return self.host.state.end.page_letter

    @property
    def page(self) -> Page:
        return PAGE_LETTERS[self.page_letter]

    @property
    def moving(self) -> bool:
        return self.host.state.end.moving

    def _guard_stop(self) -> None:
        self.host.send(self.host.state.end.stop)

    def _forget_motion(self) -> None:
        self.driving.stop()

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
        except LinkLost as exc:
            self.say(str(exc))
            self.driving.stop()
            return False
        return True

    @property
    def _speed_keys(self) -> Mapping[str, int]:
        return self.host.state.layout.profile.speed_keys

    @property
    def in_force_text(self) -> str:
        return f"{self.in_force} {letter_name(self.page, self.in_force)}"

    @property
    def page_text(self) -> str:
        return f"{self.page.value} ({self.page_letter} {self.page_name})"

    @property
    def page_name(self) -> str:
        """The app's page the board is on, as its profile names it."""
        pages = self.host.state.layout.profile.pages
        return pages.get(self.page_letter, PAGE_NAMES[self.page_letter])

    # ------------------------------------------------------------ what it shows

    def status_rows(self) -> list[Row]:
        host, state = self.host, self.host.state
        now = host.now()
        moving = self.in_force != STOP_LETTER
        rows = link_rows(host.connected, state.stats, now)
        rows += telemetry(state, now)
        page: tuple[Span, ...] = (
            ("", f" {self.page_text}   "),
            ("label", "in force "),
            ("on" if moving else "", f" {self.in_force_text} "),
            ("", f"   {hold_mode(self.driving)}"),
        )
        rows.append(Row("page", page))
        if moving and not host.connected:
            rows.append(unsent_row())
        if state.letters_ignored:
            ignored: tuple[Span, ...] = (
                ("warn", " the car does not follow the letters "),
                ("", "  UART2 may have taken over (§8.3)"),
            )
            rows.append(Row("control", ignored))
        record = state.params
        if record is None:
            rows.append(Row("params", (("", " not read yet (p reads them)"),)))
        else:
            pairs = zip(self.specs, record.values, strict=False)
            shown = tuple(f"{p.name} {param_values.to_user(p, v)}" for p, v in pairs)
            rows.append(Row("params", pairs=shown))
        return rows

    @property
    def specs(self) -> param_values.Specs:
        """The parameters' table of the board's profile."""
        return self.host.state.layout.params

    def instruments(self) -> Instruments:
        host, state = self.host, self.host.state
        now = host.now()
        specs = self.specs
        table = [(p.name, p.minimum, p.maximum) for p in specs]
        names = [p.name for p in specs]
        now_values = () if state.params is None else state.params.values
        read = dict(zip(names, now_values, strict=False))
        unsaved = [
            name
            for name, old, new in zip(names, self.baseline or (), now_values, strict=False)
            if old != new
        ]
        values = instruments.values(table, read, unsaved, [p.scale for p in specs])
        return Instruments(
            link=instruments.link(host.connected, state.stats, now),
            telemetry=instruments.telemetry(state, now),
            in_force="stopped" if not self.moving else letter_name(self.page, self.in_force),
            moving=self.moving,
            stop_unsent=self.moving and not host.connected,
            page=self.page_name,
            speed=self._speed_value(values),
            values=values,
            values_read=state.params is not None,
            wheels=None,
            wheels_age=None,
            driver=None,
        )

    def grid_cells(self) -> list[list[str]]:
        letters = grid_for(self.page)
        return [
            [
                f"{letter} {GLYPHS[r][c]} {letter_name(self.page, letter)}"
                for c, letter in enumerate(row)
            ]
            for r, row in enumerate(letters)
        ]

    def cell_names(self) -> list[list[str]]:
        return [[letter_name(self.page, x) for x in row] for row in grid_for(self.page)]

    def lit_cell(self) -> tuple[int, int] | None:
        if self.in_force == STOP_LETTER:
            return None
        letters = grid_for(self.page)
        cells = [(r, c) for r in range(3) for c in range(3)]
        return next(((r, c) for r, c in cells if letters[r][c] == self.in_force), None)

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

    def _speed_value(self, values: tuple[Value, ...]) -> Value | None:
        """What the speed keys change: the speed parameter, or (a firmware whose letters
        change its speed) those letters, whose speed no record shows; None: nothing."""
        layout = self.host.state.layout
        if layout.speed_index is not None:
            return values[layout.speed_index]
        keys = self._speed_keys
        return Value(f"speed ({'/'.join(keys)})", None, 0, 0) if keys else None

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
