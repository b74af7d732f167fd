"""Reads and verified sets on the control port as a state machine, with no I/O.

A round sends each read AGREE times at once (after the set frame, for a set): the board
answers every copy in the same tick, from the same state, and a value is reported only
when its replies agree (the line has no checksum). A round ends when every read has its
replies, or at its timeout; what did not agree is asked again in the next round, and
after `tries` rounds the query ends in QueryFailed. A set is done when the agreed value
is the one set; another value sends the set again.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass

from appmode.errors import AppmodeError
from appmode.host.outcomes import AGREE, TRIES, QueryFailed
from appmode.protocol import control, settings

ROTATE_TIMEOUT = 20.0
ROTATE_POLL = 0.1
"""Seconds between reads of the pending angle while a rotation goes on."""


def rotation_done(left: int, elapsed: float, timeout: float = ROTATE_TIMEOUT) -> bool:
    """Whether a turn in angle mode (§9.1) has ended: the pending angle read (`left`,
    0.1°) is 0; AppmodeError once it has gone on longer than `timeout` seconds."""
    if left == 0:
        return True
    if elapsed > timeout:
        raise AppmodeError(
            f"rotate: {left / 10:g}° still to turn after {timeout:g} s (is the car held, "
            "or max_speed 0?)"
        )
    return False


@dataclass(frozen=True, slots=True)
class ReadDone:
    values: dict[str, int]
    """The values read, by name, in the order asked."""
    text: str


ControlOutcome = ReadDone | QueryFailed


class ReadQuery:
    """Read values by name (settings, `pending_angle`, `speed_a`…, `position_a`…), or
    set one setting (`change`) and verify it by reading it back."""

    def __init__(
        self,
        names: Iterable[str] = (),
        change: tuple[str, int] | None = None,
        timeout: float = 0.1,
        tries: int = TRIES,
        where: str = "the board",
    ) -> None:
        self.set_frame: control.SetSetting | None = None
        if change is not None:
            setting = settings.lookup(change[0])
            error = settings.value_error(setting, change[1])
            if error is not None:
                raise ValueError(error)
            self.set_frame = control.SetSetting(setting, change[1])
            names = [setting.name]
        self.reads = list(dict.fromkeys(settings.read_named(name) for name in names))
        if not self.reads:
            raise ValueError("nothing to read")
        self.timeout = timeout
        self.tries = tries
        self.where = where
        self.rounds = 0
        self.deadline = 0.0
        self.agreed: dict[str, int] = {}
        self._replies: dict[int, list[int]] = {}
        self._heard = False
        self._refused: int | None = None
        """The value the board showed after the last set, when not the one set."""

    @property
    def names(self) -> list[str]:
        return [r.name for r in self.reads]

    def start(self, now: float) -> bytes:
        """The bytes to send first."""
        return self._round(now)

    def _round(self, now: float) -> bytes:
        self.rounds += 1
        self.deadline = now + self.timeout
        want = [r for r in self.reads if r.name not in self.agreed]
        self._replies = {r.reply_id: [] for r in want}
        frames: list[control.HostFrame] = [] if self.set_frame is None else [self.set_frame]
        frames += [control.ReadFrame(r) for r in want for _ in range(AGREE)]
        return b"".join(control.encode(frame) for frame in frames)

    def on_reply(self, reply: control.Reply, now: float) -> tuple[bytes, ControlOutcome | None]:
        """A reply arrived: (bytes to send, outcome or None)."""
        values = self._replies.get(reply.id)
        if values is None:
            return b"", None
        values.append(reply.value)
        self._heard = True
        if all(len(v) >= AGREE for v in self._replies.values()):
            return self._end_round(now)
        return b"", None

    def on_time(self, now: float) -> tuple[bytes, ControlOutcome | None]:
        """Call as time passes: a next round, a failure, or nothing yet."""
        if now < self.deadline:
            return b"", None
        return self._end_round(now)

    def _end_round(self, now: float) -> tuple[bytes, ControlOutcome | None]:
        for r in self.reads:
            values = self._replies.get(r.reply_id, [])
            if len(values) >= AGREE and len(set(values)) == 1:
                self.agreed[r.name] = values[0]
        if self.set_frame is not None:
            name, wanted = self.set_frame.setting.name, self.set_frame.value
            got = self.agreed.pop(name, None)
            if got == wanted:
                return b"", ReadDone({name: got}, f"set {name} = {got} (verified)")
            if got is not None:
                self._refused = got
        elif len(self.agreed) == len(self.reads):
            read = {r.name: self.agreed[r.name] for r in self.reads}
            text = ", ".join(f"{name} = {value}" for name, value in read.items())
            return b"", ReadDone(read, text)
        if self.rounds < self.tries:
            return self._round(now), None
        return b"", QueryFailed(self._failure())

    def _failure(self) -> str:
        if self.set_frame is not None and self._refused is not None:
            return (
                f"{self.set_frame.setting.name} still reads {self._refused} on {self.where} "
                f"after {self.rounds} sets of {self.set_frame.value}: the board does not take it"
            )
        missing = [r.name for r in self.reads if r.name not in self.agreed]
        what = "no two replies agreed" if self._heard else "no reply"
        return (
            f"{what} reading {', '.join(missing)} on {self.where} after {self.rounds} "
            "tries: is this the board's control port (UART2, 115200 bps)? The reference "
            "firmware does not answer reads (see appmode protocol 13)"
        )
