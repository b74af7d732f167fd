"""The board's telemetry: the start-up text, the A, B and C records on the profile's
schedule (§3.4, §13), on UART3 or, in APP mode, on UART2 (§12); and the reference
firmware's status burst on UART2 after each record (§13.1)."""

from __future__ import annotations

import math

from appmode.board.chip import c_int, times_float32
from appmode.board.core import Core
from appmode.board.vehicle import battery_percent, wrap_degrees
from appmode.protocol import app, control
from appmode.protocol.profile_file import Field

APP_BYTE = 10 / 9600
"""A byte's time on the APP port's wire."""
GYRO_PER_DEGREE = 16.4
"""The gyro's raw z rate per °/s (±2000 °/s full scale: our decision, §13.1)."""


class Telemetry:
    """When the next record goes out, which it is, and its bytes."""

    def __init__(self, core: Core) -> None:
        self.core = core
        profile = core.profile
        self.startup = profile.startup_text
        self.record_ms = profile.startup_ms if self.startup else profile.first_record_ms
        """When the next record goes out, in ms from boot."""
        self.burst_ms = math.inf
        """When UART2's status burst goes out (firmware_uart2)."""
        self._show_a = profile.first_record == "A"
        self._c_pending = False
        self.c_on_wire_until = -math.inf
        """Until when a C record is going out (a read then is lost on some boards)."""
        self._made: dict[bytes, tuple[tuple[int, ...], bytes]] = {}  # letter: last values, bytes

    def request_c(self, now: float, shown: str, port: str) -> None:
        """`{Q:P}`: a C record in the next slot, in place of A or B (§5.1)."""
        core = self.core
        if core.profile.read_lost_in_c and now < self.c_on_wire_until:
            core.note(now, "rejected", f"{shown}: lost: a C record is going out (§13)", port)
            return
        self._c_pending = True
        core.note(now, "applied", f"{shown}: read parameters, C record in next slot", port)

    def send_record(self) -> None:
        """The record due at `record_ms` goes out, and the next is planned."""
        core = self.core
        profile = core.profile
        at = self.record_ms
        data = self.startup
        if data:
            self.startup = b""
            core.out3 += data
            self.record_ms = max(profile.first_record_ms, at)
            return
        if self._c_pending:
            self._c_pending = False
            values = tuple(c_int(v) if profile.c_saturates else int(v) for v in core.params)
            data = self._bytes(b"C", values)
            if profile.file is not None and profile.file.replies:
                data = "".join(profile.file.replies).encode() + data
            self.c_on_wire_until = core.boot + at / 1000 + len(data) * APP_BYTE
        elif profile.file is not None:
            fields = profile.file.a if self._show_a else profile.file.b
            data = self._data_record(b"A" if self._show_a else b"B", fields, at)
        else:
            data = self._a_record(at) if self._show_a else self._b_record(at)
        self._show_a = not self._show_a
        if core.mode("app_mode"):
            core.out2 += data  # §12: records go out on UART2, UART3's transmitter is idle
        else:
            core.out3 += data
        if profile.firmware_uart2:  # written once the record has gone out
            self.burst_ms = float(at + math.ceil(len(data) * profile.byte_ms))
        self.record_ms = at + profile.record_period_ms(len(data))

    def send_burst(self) -> None:
        """What reaches the host of the status the reference loop writes to UART2 after
        each APP record (§13.1): `FF FE` and the gyro z rate's low byte."""
        rate = self.core.vehicle.vz * self.core.vehicle.yaw_gain * GYRO_PER_DEGREE
        self.core.out2 += control.HEADER + bytes([(int(rate) + 0x8000) & 0xFF])
        self.burst_ms = math.inf

    def _bytes(self, letter: bytes, values: tuple[int, ...]) -> bytes:
        """A record's bytes; formatted again only when its values changed (a car driving
        steadily sends the same records)."""
        made = self._made.get(letter)
        if made is None or made[0] != values:
            made = self._made[letter] = (values, app.record_bytes(letter, values))
        return made[1]

    def _whole(self, value: float) -> int:
        return math.trunc(value) if self.core.profile.truncate else round(value)

    def _battery(self, ms: int) -> int:
        core = self.core
        volts = core.vehicle.centivolts if core.powered(ms) else 0.0
        return battery_percent(volts, core.profile.battery_floor)

    def _a_record(self, ms: int) -> bytes:
        core = self.core
        profile, v = core.profile, core.vehicle
        layout = profile.a_layout
        sign = -1 if core.mode("encoder_reverse") else 1
        fields = [0, 0, 0, 0]
        for i, value in zip(layout.motion, (v.vx, v.vy, v.vz), strict=False):
            if profile.float32:
                shown = self._whole(times_float32(sign * value, layout.scale))
            else:
                shown = self._whole(sign * value * layout.scale)
            fields[i] = shown if layout.signed else abs(shown) % 256
        if layout.battery is not None:
            fields[layout.battery] = self._battery(ms)
        return self._bytes(b"A", tuple(fields))

    def _data_record(self, letter: bytes, fields: tuple[Field, ...], ms: int) -> bytes:
        """A data profile's record, with no physics: three motion fields show x, y and z;
        others the forward speed, a wheel's (`left`, `right` in its name) with the turn;
        the battery field the battery; the rest 0."""
        v = self.core.vehicle
        motion = [i for i, field in enumerate(fields) if field.motion]
        values = [0] * len(fields)
        for n, i in enumerate(motion):
            field = fields[i]
            if len(motion) == 3:
                speed = (v.vx, v.vy, v.vz)[n]
            else:
                turn = ("left" in field.name) - ("right" in field.name)
                speed = v.vy + turn * v.vz
            shown = self._whole(field.scale * speed)
            shown = shown if field.signed else abs(shown)
            values[i] = shown % field.wrap if field.wrap else shown
        for i, field in enumerate(fields):
            if field.battery:
                values[i] = self._battery(ms)
        return self._bytes(letter, tuple(values))

    def _b_record(self, ms: int) -> bytes:
        core = self.core
        profile, v = core.profile, core.vehicle
        yaw = -v.heading if core.mode("gyro_reverse") else v.heading
        pitch, roll = self._whole(v.pitch), self._whole(v.roll)
        yaw_shown = wrap_degrees(yaw, profile.yaw_low, profile.truncate)
        return self._bytes(b"B", (pitch, roll, yaw_shown, self._battery(ms)))
