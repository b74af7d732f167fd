"""The board's firmware as a deterministic state machine with an injected clock.

`Board.receive(data, now)` applies host bytes at time `now`; `Board.poll(now)` returns
the telemetry due by `now`. The control port has its own pair, `receive_uart2` and
`poll_uart2` (docs/protocol.md §8–§12), with the same clock and the same state. Time
only moves forward (an earlier `now` counts as the board's current time). The control
loop runs in fixed ticks of TICK seconds from boot; records go out on the profile's
schedule (§3.4, §13), on a millisecond grid. The same inputs at the same times give the
same bytes, whatever the pattern of `poll` calls. Every way a profile differs is a
switch of `profiles.Profile`.
"""

from __future__ import annotations

import math
from collections import deque
from dataclasses import dataclass
from typing import cast

from appmode.board import kinematics
from appmode.board.chip import c_int, float32, times_float32
from appmode.board.intake import INT_PARAMS, ControlIntake, FirmwareIntake, Frame
from appmode.board.profiles import SHEET, Profile
from appmode.board.store import MemoryStore, Store
from appmode.board.vehicle import YAW_GAIN, Vehicle, battery_percent, wrap_degrees
from appmode.errors import AppmodeError
from appmode.protocol import app, app_decoders, control, control_decoders, params, settings
from appmode.protocol.directions import PAGE_LETTERS, Page, motion_for, target_velocity
from appmode.protocol.escaping import escape
from appmode.protocol.params import DriveType

TICK = 0.01
TICK_MS = 10
SLOT = 0.05
"""The sheet profile's time between records."""
APP_BYTE = 10 / 9600
"""A byte's time on the APP port's wire."""
_APP_MODE, _ENCODER_REPORT = params.MODE_BIT["app_mode"], params.MODE_BIT["encoder_report"]
MAX_CATCH_UP = 200
"""Ticks run one by one when the board falls behind; beyond that it skips ahead."""
MAX_RAMP = 2000
"""Ticks of a ramp run when the board skips ahead (20 s: any ramp has settled)."""
MAX_NOTES = 1000
"""Log lines kept until taken: an edge that never reads them costs bounded memory."""
REPORT_MS = 50
"""The encoder report's period on UART2 (§12)."""
POSITION_GAIN = 2.0
"""Position mode drives each axis at this many times its remaining distance a second
(at most max_speed): the car slows as it nears the target and holds it (§9.3)."""
ANGLE_SPEED = 0.5
"""Angle mode turns at this fraction of max_speed (§9.1)."""
COPY_MS = 5
"""How often the reference loop takes UART2's last frame (§13.1)."""
GYRO_PER_DEGREE = 16.4
"""The gyro's raw z rate per °/s (±2000 °/s full scale: our decision, §13.1)."""
UART3, UART2 = "uart3", "uart2"
"""The ports, as the board's log names them."""


@dataclass(frozen=True, slots=True)
class Note:
    """One line of the board's own log: what it received and what it did with it."""

    time: float
    level: str  # "applied", "rejected", "warning" or "info"
    text: str
    port: str = UART3


class Board:
    """The firmware: pages, directions, parameters, telemetry schedule, flash."""

    def __init__(
        self,
        store: Store | None = None,
        *,
        drive: params.DriveType | None = None,
        now: float = 0.0,
        centivolts: float | None = None,
        profile: Profile = SHEET,
    ) -> None:
        self.profile = profile
        self.store: Store = store if store is not None else MemoryStore()
        self.notes: deque[Note] = deque(maxlen=MAX_NOTES)
        saved = None
        if profile.saves:
            saved, warning = self.store.load()
            if warning is not None:
                self._note(now, "warning", warning)
        values = saved if saved is not None else profile.defaults
        self.params: list[float] = list(values[: params.PARAM_COUNT])
        self.gyro_calibration = (
            values[params.PARAM_COUNT] if len(values) > params.PARAM_COUNT else 0
        )
        profile.check(drive=drive is not None, flash=False)
        if drive is not None:
            mode = int(self.params[params.SYSTEM_MODE]) & ~params.DRIVE_MASK
            self.params[params.SYSTEM_MODE] = mode | int(drive)
        self.page = Page.DIRECTION
        self.direction = 0
        self.turn = 0  # a rotation held apart from the direction (sticky_rotation)
        self.vehicle = Vehicle()
        if centivolts is not None:
            self.vehicle.centivolts = centivolts
        self.errors = 0
        self.warnings = 0
        self._boot = now
        self._tick_ms = 0  # the next control tick, in ms from boot
        self._startup = profile.startup_text
        self._record_ms = profile.startup_ms if self._startup else profile.first_record_ms
        self._show_a = profile.first_record == "A"
        self._copy_ms = 0.0 if profile.firmware_uart2 else math.inf  # the next COPY_MS tick
        self._burst_ms = math.inf  # when UART2's status burst goes out (firmware_uart2)
        self._c_pending = False
        self._c_on_wire_until = -math.inf
        self._outbox = bytearray()
        self._decoder = app_decoders.HostDecoder()
        self._intake = FirmwareIntake(profile.steer_in_frames, profile.frame_restarts)
        # the control port (§8–§12)
        self.uart2_control = False
        self.uart2_received = 0
        self.uart2_errors = 0
        self.pending_angle = 0.0  # 0.1°, signed (§9.1)
        self._command: control.HostFrame | None = None  # the last motion frame obeyed
        self._position_goal: tuple[float, float, float] | None = None
        self._target_velocity: tuple[float, float, float] = (0.0, 0.0, 0.0)
        self._target_for: tuple[object, ...] | None = None  # what _target was worked out for
        self._target_is: tuple[float, float, float] = (0.0, 0.0, 0.0)  # and what it was
        self._reads: list[settings.Read] = []
        self._out2 = bytearray()
        self._frames = control_decoders.FrameDecoder(self.drive_type)
        self._app2 = app_decoders.HostDecoder()
        self._intake2 = FirmwareIntake(profile.steer_in_frames, profile.frame_restarts)
        self._control_intake = ControlIntake()
        self._last_frame: bytes | None = None  # UART2's last frame, not yet taken

    # ------------------------------------------------------------ clock

    def next_slot(self) -> float:
        """When the board next sends something: a record, a reply, an encoder report."""
        return min(self.next_sends())

    def next_sends(self) -> tuple[float, float]:
        """When the board next sends on UART3 and on UART2 (infinity: nothing planned).
        Records go out on UART3, or on UART2 in APP mode (§12); replies and encoder
        reports on UART2."""
        uart3, uart2 = float(self._record_ms), self._burst_ms
        mode = int(self.params[params.SYSTEM_MODE])
        if mode & _APP_MODE:
            uart3, uart2 = uart2, uart3
        if self._reads:
            uart2 = min(uart2, self._tick_ms)
        elif mode & _ENCODER_REPORT and not mode & _APP_MODE:
            uart2 = min(uart2, -(-self._tick_ms // REPORT_MS) * REPORT_MS)
        return self._boot + uart3 / 1000, self._boot + uart2 / 1000

    def next_reply(self) -> float:
        """When the board next answers a read on UART2 (infinity when none is pending)."""
        return self._boot + self._tick_ms / 1000 if self._reads else math.inf

    def advance(self, now: float) -> None:
        """Run every tick and record due by `now`."""
        due = math.floor((now - self._boot) * 1000 + 1e-6)
        behind = (due - self._tick_ms) // TICK_MS
        if behind > MAX_CATCH_UP:
            skipped = behind - MAX_CATCH_UP
            self._control(skipped)
            self._tick_ms += skipped * TICK_MS
            if self._record_ms < self._tick_ms:
                period = self.profile.period_ms or TICK_MS
                late = self._tick_ms - self._record_ms
                self._record_ms += -(-late // period) * period
            self._copy_ms = max(self._copy_ms, self._tick_ms)
        while (at := min(self._tick_ms, self._record_ms, self._copy_ms, self._burst_ms)) <= due:
            if self._copy_ms == at:  # before the control tick of the same millisecond
                self._take_frame(self._boot + at / 1000)
                self._copy_ms += COPY_MS
            elif self._burst_ms == at:
                self._out2 += self._status_burst()
                self._burst_ms = math.inf
            elif self._tick_ms == at:
                if self._tick_ms:
                    self._control(1)
                self._uart2_tick()
                self._tick_ms += TICK_MS
                self._rest(due)
            else:
                self._send_record()

    def _rest(self, due: int) -> None:
        """Run at once the control ticks up to the next other event (by `due`) while the
        car rests and stays at rest: all such a tick does is drain the battery (exact:
        Vehicle.rest drains it tick by tick). An idle car costs no 100 Hz step."""
        vehicle = self.vehicle
        if (
            vehicle.vx
            or vehicle.vy
            or vehicle.vz
            or any(self._target_velocity)
            or self.uart2_control
            or self._reads
            or self._mode("encoder_report")
        ):
            return
        last = min(due, self._record_ms, self._copy_ms - 1, self._burst_ms - 1)
        if last < self._tick_ms or self._powered(self._tick_ms) != self._powered(int(last)):
            return  # no tick before the next event, or the motors' power comes on
        ticks = int(last - self._tick_ms) // TICK_MS + 1
        vehicle.rest(ticks, TICK)
        self._tick_ms += ticks * TICK_MS

    # ------------------------------------------------------------ I/O-free edges

    def receive(self, data: bytes, now: float) -> None:
        """Apply host bytes that arrived at `now`."""
        self.advance(now)
        self._receive_app(data, now, UART3)

    def _receive_app(self, data: bytes, now: float, port: str) -> None:
        if self.profile.firmware_frames:
            intake = self._intake if port == UART3 else self._intake2
            for item in intake.feed(data):
                if isinstance(item, Frame):
                    self._apply_frame(item, now, port)
                else:
                    self._apply(item.event, now, port, framed=item.framed)
        else:
            decoder = self._decoder if port == UART3 else self._app2
            for event in decoder.feed(data):
                self._apply(event, now, port)

    def poll(self, now: float) -> bytes:
        """The telemetry bytes due by `now`."""
        self.advance(now)
        out = bytes(self._outbox)
        self._outbox.clear()
        return out

    def receive_uart2(self, data: bytes, now: float) -> None:
        """Apply bytes that arrived on the control port at `now` (§8)."""
        self.advance(now)
        before = self.uart2_received
        self.uart2_received += len(data)
        if self._mode("app_mode"):
            self._receive_app(data, now, UART2)
        elif self.profile.firmware_uart2:
            for frame in self._control_intake.feed(data):
                self._last_frame = frame
        else:
            for event in self._frames.feed(data):  # never in APP mode: _app2 has that
                self._apply_control(cast(control.HostEvent, event), now)
        at = self.profile.takeover_byte
        if not self.uart2_control and before < at <= self.uart2_received:
            self.uart2_control = True
            self.direction, self.turn = 0, 0
            self._note(
                now,
                "info",
                f"UART2 takes over the motion at its byte {at}; the APP port's direction "
                "is dropped and its drive letters are ignored from now on (§8.3)",
                UART2,
            )

    def poll_uart2(self, now: float) -> bytes:
        """The control port's bytes due by `now`: replies, encoder reports, and records
        while APP mode is on."""
        self.advance(now)
        out = bytes(self._out2)
        self._out2.clear()
        return out

    def take_notes(self) -> list[Note]:
        notes = list(self.notes)
        self.notes.clear()
        return notes

    # ------------------------------------------------------------ firmware

    @property
    def drive_type(self) -> params.DriveType:
        if not self.profile.drive_types:
            return params.DriveType.OMNI
        drive = params.drive_type(int(self.params[params.SYSTEM_MODE]))
        assert drive is not None, "set frames with an invalid drive type are rejected"
        return drive

    def _powered(self, ms: int) -> bool:
        """Whether the motors run at `ms` after power-up (not in the profile's dead time,
        when the battery voltage also reads 0)."""
        return ms >= self.profile.dead_time * 1000

    def _mode(self, name: str) -> bool:
        return bool(int(self.params[params.SYSTEM_MODE]) & params.MODE_BIT[name])

    def _control(self, ticks: int) -> None:
        """`ticks` control ticks of TICK seconds."""
        profile = self.profile
        speed = self.params[params.MAX_SPEED]
        if 0 < speed < profile.stall_speed:
            self.params[params.MAX_SPEED] = speed = profile.stall_speed
        vehicle = self.vehicle
        if self.uart2_control and profile.firmware_uart2:
            self._drive_firmware_uart2(ticks)
            return
        if self.uart2_control and not self._mode("app_mode"):
            for _ in range(min(ticks, MAX_RAMP)):  # beyond that the car has long settled
                self._drive_uart2(speed)
            return
        if profile.ramp is None:
            self._target_velocity = self._target(speed)
            vehicle.step(self._target_velocity, ticks * TICK)
        else:
            pushes = self._pushes() if self._powered(self._tick_ms) else (0, 0, 0)
            rounding = float32 if profile.float32 else float
            for _ in range(min(ticks, MAX_RAMP)):  # beyond that a ramp has long settled
                vehicle.ramp(pushes, speed, profile.ramp, profile.coast, TICK, rounding)
            self._target_velocity = (vehicle.vx, vehicle.vy, vehicle.vz)

    def _drive_firmware_uart2(self, ticks: int) -> None:
        """Control ticks as the reference loop runs them once UART2 drives (§13.1): the
        last velocity frame taken sets the velocity as it is; with none the car keeps
        the velocity it had at the take-over."""
        command, vehicle = self._command, self.vehicle
        if isinstance(command, control.VelocityFrame):
            vehicle.vx, vehicle.vy, vehicle.vz = map(float, command.values)
        self._target_velocity = (vehicle.vx, vehicle.vy, vehicle.vz)
        vehicle.step(self._target_velocity, ticks * TICK)

    def _take_frame(self, now: float) -> None:
        """A COPY_MS tick of the reference loop (§13.1): once UART2 drives, its last frame
        is taken, if none is being received; only a velocity frame moves the car."""
        frame = self._last_frame
        if frame is None or not self.uart2_control or self._control_intake.receiving:
            return
        self._last_frame = None
        shown = frame.hex(" ").upper()
        mode = frame[2]
        if mode not in self.profile.control_modes:
            name = control.MODES.get(mode, f"mode {mode:02X}")
            self._note(now, "rejected", f"{shown}: {name} frame: no effect (§13.1)", UART2)
            return
        event = control_decoders.FrameDecoder().feed(frame)[0]
        assert isinstance(event, control.VelocityFrame), "control_modes holds only 01 here"
        self._command = event
        self._note(now, "applied", f"{shown}: velocity {event.values}, as it is (§13.1)", UART2)

    def _status_burst(self) -> bytes:
        """What reaches the host of the status the reference loop writes to UART2 after
        each APP record (§13.1): `FF FE` and the gyro z rate's low byte."""
        rate = self.vehicle.vz * YAW_GAIN * GYRO_PER_DEGREE
        return control.HEADER + bytes([(int(rate) + 0x8000) & 0xFF])

    def _drive_uart2(self, speed: float) -> None:
        """One control tick with UART2 in control: its last motion frame, angle mode's
        pending rotation, position mode's goal (§9)."""
        command, vehicle = self._command, self.vehicle
        x = y = z = 0.0
        if isinstance(command, control.VelocityFrame):
            x, y, z = self._velocity_target(command, speed)
        elif isinstance(command, control.MotorFrame):
            x, y, z = kinematics.body(self.drive_type, tuple(map(float, command.speeds)))
        elif self._position_goal is not None:
            travel = (vehicle.travel_x, vehicle.travel_y, vehicle.travel_z)
            x, y, z = (
                _clamp((goal - done) * POSITION_GAIN, speed)
                for goal, done in zip(self._position_goal, travel, strict=True)
            )
        if self.pending_angle:
            z = math.copysign(speed * ANGLE_SPEED, self.pending_angle)
        self._target_velocity = (x, y, z)
        vehicle.step(self._target_velocity, TICK)
        if self.pending_angle:
            left = self.pending_angle - vehicle.vz * YAW_GAIN * TICK * 10
            self.pending_angle = left if left * self.pending_angle > 0 else 0.0

    def _wheel_targets(self) -> tuple[float, ...]:
        """What each wheel is driven at: a motor frame's speeds while UART2 drives by
        one, else the wheels of the body's target velocity."""
        command = self._command
        if isinstance(command, control.MotorFrame) and self.uart2_control:
            return tuple(map(float, command.speeds))
        return kinematics.wheels(self.drive_type, *self._target_velocity)

    def _angle_mode(self, frame: control.VelocityFrame) -> bool:
        return frame.angle and self.drive_type is not DriveType.DIFF_GYRO

    def _velocity_target(
        self, frame: control.VelocityFrame, speed: float
    ) -> tuple[float, float, float]:
        """A velocity frame's body velocity on this drive type (§9.1)."""
        a, b, c = frame.values
        if self._angle_mode(frame):
            c = 0
        drive = self.drive_type
        if drive is DriveType.DIFF_GYRO:
            left, right = _duty(a, speed), _duty(b, speed)
            return (0.0, (left + right) / 2, (left - right) / 2)
        if drive.differential:
            return (0.0, _duty(b, speed), _duty(c, speed))
        return (_clamp(a, speed), _clamp(b, speed), _clamp(c, speed))

    def _uart2_tick(self) -> None:
        """What UART2 sends in a control tick: the replies to reads received since the
        last tick (§11), and the encoder report every REPORT_MS while bit 6 is set (§12)."""
        if self._reads:
            for read in self._reads:
                value = self._read_value(read)
                self._out2 += control.encode(control.Reply(read.reply_id, value))
            self._reads.clear()
        if (
            self._tick_ms % REPORT_MS == 0
            and self._mode("encoder_report")
            and not self._mode("app_mode")
            and self.profile.answers_reads
        ):
            targets = self._encoders(self._wheel_targets())
            actuals = self._encoders(self._wheels())
            self._out2 += control.encode(control.EncoderReport(targets, actuals))

    def _wheels(self) -> tuple[float, ...]:
        v = self.vehicle
        return kinematics.wheels(self.drive_type, v.vx, v.vy, v.vz)

    def _encoders(self, values: tuple[float, ...]) -> tuple[int, ...]:
        """Wheel values as the encoders give them: whole, signed by encoder_reverse."""
        sign = -1 if self._mode("encoder_reverse") else 1
        count = control.motor_count(self.drive_type)
        values = (values + (0.0,) * count)[:count]
        return tuple(_int32(sign * value) for value in values)

    def _read_value(self, read: settings.Read) -> int:
        """The value a read's reply carries (§11)."""
        setting = settings.BY_NAME.get(read.name)
        if setting is not None:
            held = self.gyro_calibration if setting.param is None else self.params[setting.param]
            return int(held) & params.U32
        if read.ss == settings.PENDING_ANGLE:
            return _int32(self.pending_angle)
        v = self.vehicle
        if read.ss >= settings.POSITION_BASE:
            wheels = kinematics.wheels(self.drive_type, v.travel_x, v.travel_y, v.travel_z)
            index = read.ss - settings.POSITION_BASE
        else:
            wheels = self._wheels()
            index = read.ss - settings.SPEED_BASE
        encoders = self._encoders(wheels)
        return encoders[index] if index < len(encoders) else 0  # no wheel D on an omni

    def _target(self, speed: float) -> tuple[float, float, float]:
        """The velocity the APP port's direction asks for; worked out again only when
        what it depends on changed (it is asked 100 times a second)."""
        key = (self.page, self.direction, speed, self.params[params.SYSTEM_MODE])
        if key != self._target_for:
            self._target_for = key
            if self._mode("motor_reverse"):
                speed = -speed
            self._target_is = target_velocity(
                self.page, self.direction, speed, self.drive_type.differential, self.profile.buttons
            )
        return self._target_is

    def _pushes(self) -> tuple[int | None, ...]:
        """Which way a ramping board pushes x, y, z this tick (vehicle.ramp): with no
        direction x and y coast, and z too on the button page; on the direction page a
        rotation that ended stops at once (§13.1)."""
        motion = motion_for(self.page, self.direction, self.profile.buttons)
        z: int | None = self.turn or (0 if self.page is Page.DIRECTION else None)
        if motion is None:
            return (None, None, z)
        x, y, turn = (int(math.copysign(1, f)) if f else 0 for f in motion.holonomic)
        return (x, y, turn or z)

    def _send_record(self) -> None:
        profile = self.profile
        at = self._record_ms
        data = self._startup
        if data:
            self._startup = b""
            self._outbox += data
            self._record_ms = max(profile.first_record_ms, at)
            return
        if self._c_pending:
            self._c_pending = False
            values = tuple(c_int(v) if profile.c_saturates else int(v) for v in self.params)
            data = app.encode(app.ParamsRecord(values))
            self._c_on_wire_until = self._boot + at / 1000 + len(data) * APP_BYTE
            self._show_a = not self._show_a
        else:
            data = app.encode(self._a_record(at) if self._show_a else self._b_record(at))
            self._show_a = not self._show_a
        if self._mode("app_mode"):
            self._out2 += data  # §12: records go out on UART2, UART3's transmitter is idle
        else:
            self._outbox += data
        if profile.firmware_uart2:  # written once the record has gone out
            self._burst_ms = at + math.ceil(len(data) * profile.byte_ms)
        self._record_ms = at + profile.record_period_ms(len(data))

    def _whole(self, value: float) -> int:
        return math.trunc(value) if self.profile.truncate else round(value)

    def _battery(self, ms: int) -> int:
        volts = self.vehicle.centivolts if self._powered(ms) else 0.0
        return battery_percent(volts, self.profile.battery_floor)

    def _a_record(self, ms: int) -> app.Velocity:
        layout = self.profile.a_layout
        v = self.vehicle
        sign = -1 if self._mode("encoder_reverse") else 1
        fields = [0, 0, 0, 0]
        for i, value in zip(layout.motion, (v.vx, v.vy, v.vz), strict=False):
            if self.profile.float32:
                shown = self._whole(times_float32(sign * value, layout.scale))
            else:
                shown = self._whole(sign * value * layout.scale)
            fields[i] = shown if layout.signed else abs(shown) % 256
        if layout.battery is not None:
            fields[layout.battery] = self._battery(ms)
        return app.Velocity(fields[0], fields[1], fields[2], fields[3])

    def _b_record(self, ms: int) -> app.Attitude:
        profile, v = self.profile, self.vehicle
        yaw = -v.heading if self._mode("gyro_reverse") else v.heading
        return app.Attitude(
            self._whole(v.pitch),
            self._whole(v.roll),
            wrap_degrees(yaw, profile.yaw_low, profile.truncate),
            self._battery(ms),
        )

    def _note(self, now: float, level: str, text: str, port: str = UART3) -> None:
        self.notes.append(Note(now, level, text, port))

    def _steer(self, event: app.ByteEvent) -> str:
        """Apply one byte's direction logic (§2.1, §4; §13's rotation rule); what it did."""
        sticky = self.profile.sticky_rotation
        if isinstance(event, app.SwitchPage):
            self.page = PAGE_LETTERS[event.letter]
            self.direction = 0
            if self.page is Page.BUTTON:
                self.turn = 0
            return f"stop, {self.page.value} page"
        if isinstance(event, app.Move) and (
            self.page is Page.DIRECTION or not event.numeric or self.profile.numeric_buttons
        ):
            motion = motion_for(self.page, event.direction, self.profile.buttons)
            if motion is None:
                self.direction = 0
                self.turn = 0
                return f"stop ({event.letter} is no button here)"
            x, y, z = motion.holonomic
            if sticky and self.page is Page.BUTTON and z and not (x or y):
                self.direction, self.turn = 0, int(math.copysign(1, z))
            else:
                self.direction, self.turn = event.direction, 0
            return f"{motion.name} ({self.page.value} page)"
        self.direction = 0
        if self.page is Page.BUTTON or not sticky:
            self.turn = 0
        return "stop" if not self.turn else "stop; the rotation goes on (§13)"

    def _apply(self, event: app.HostEvent, now: float, port: str, framed: bool = False) -> None:
        shown = escape(event.raw)
        if isinstance(event, (app.Move, app.Stop, app.SwitchPage, app.Noise)):
            if isinstance(event, app.Noise):
                self.errors += not framed
            if port == UART3 and self.uart2_control:
                if not framed:
                    self._note(now, "rejected", f"{shown}: ignored: UART2 drives (§8.3)", port)
                return
            before = (self.direction, self.turn, self.page)
            did = self._steer(event)
            if isinstance(event, app.Noise):
                did = f"unrecognised byte, {did}"
            if not framed:
                level = "rejected" if isinstance(event, app.Noise) else "applied"
                self._note(now, level, f"{shown}: {did}", port)
            elif before != (self.direction, self.turn, self.page):
                self._note(now, "applied", f"{shown} in a frame: {did} (§13)", port)
        elif isinstance(event, app.BadFrame):
            self.errors += 1
            self._note(now, "rejected", f"{shown}: {event.reason}", port)
        elif isinstance(event, app.SetParam):
            self._set_param(event.index, event.value)
            self._note(now, "applied", f"{shown}: {event.name} = {event.value}", port)
        else:
            if event.warning is not None:
                self.warnings += 1
                self._note(now, "warning", f"{shown}: {event.warning}", port)
            (self._read if isinstance(event, app.ReadParams) else self._save)(now, shown, port)

    def _apply_frame(self, frame: Frame, now: float, port: str) -> None:
        shown = escape(frame.raw)
        if frame.action == "read":
            self._read(now, shown, port)
        elif frame.action == "save":
            self._save(now, shown, port)
        elif frame.action == "ignored" or frame.index not in self.profile.settable:
            reason = frame.reason or f"parameter {frame.index} is not settable on this board"
            self._note(now, "rejected", f"{shown}: ignored: {reason}", port)
        else:
            index = frame.index
            kept = c_int(frame.value) if index in INT_PARAMS else frame.value
            self.params[index] = kept
            name = params.PARAMS[index].name
            self._note(now, "applied", f"{shown}: {name} = {kept:.10g}", port)

    def _set_param(self, index: int, value: int) -> None:
        """Set a parameter from either port; a new drive type changes how UART2's
        mode-02 frames are read."""
        self.params[index] = value
        if index == params.SYSTEM_MODE:
            self._frames.drive = self.drive_type

    def _read(self, now: float, shown: str, port: str) -> None:
        if self.profile.read_lost_in_c and now < self._c_on_wire_until:
            self._note(now, "rejected", f"{shown}: lost: a C record is going out (§13)", port)
            return
        self._c_pending = True
        self._note(now, "applied", f"{shown}: read parameters, C record in next slot", port)

    def _save(self, now: float, shown: str, port: str) -> None:
        if not self.profile.saves:
            self._note(now, "rejected", f"{shown}: this board saves nothing (§13)", port)
            return
        saved = (*params.saved_form([int(v) for v in self.params]), self.gyro_calibration)
        try:
            self.store.save(saved)
        except AppmodeError as exc:
            self.errors += 1
            self._note(now, "rejected", f"{shown}: save failed: {exc}", port)
            return
        nine, calibration = list(saved[: params.PARAM_COUNT]), saved[params.PARAM_COUNT]
        self._note(now, "applied", f"{shown}: saved {nine} (gyro calibration {calibration})", port)

    def _load(self, values: tuple[int, ...] | tuple[float, ...]) -> None:
        """Load settings into the running copy; system_mode's unsaved bits stay (§10)."""
        mode = int(self.params[params.SYSTEM_MODE]) & params.UNSAVED_MASK
        self.params = [float(v) for v in values[: params.PARAM_COUNT]]
        self.params[params.SYSTEM_MODE] = int(self.params[params.SYSTEM_MODE]) | mode
        self.gyro_calibration = int(values[params.PARAM_COUNT]) if len(values) > 9 else 0
        self._frames.drive = self.drive_type

    def _apply_control(self, event: control.HostEvent, now: float) -> None:
        """One event of UART2's binary stream (§9–§11)."""
        shown = event.raw.hex(" ").upper()
        if isinstance(event, (control.Garbage, control.BadFrame)):
            self.uart2_errors += 1
            self._note(now, "rejected", f"{shown}: {event.reason}", UART2)
            return
        mode = event.raw[2]
        if mode not in self.profile.control_modes:
            self.uart2_errors += 1
            self._note(
                now,
                "rejected",
                f"{shown}: ignored: the {self.profile.name} board has no "
                f"{control.MODES[mode]} frames on UART2 (§13)",
                UART2,
            )
            return
        if isinstance(event, (control.VelocityFrame, control.MotorFrame)):
            self._command, self._position_goal = event, None
            did = f"{control.MODES[mode]} {event.values}"
            if isinstance(event, control.VelocityFrame) and self._angle_mode(event):
                self.pending_angle += event.c
                did += f", angle mode: {self.pending_angle / 10:g}° pending"
            elif event.raw == control.STOP and self.pending_angle:
                self.pending_angle = 0.0  # the stop frame stops a rotation too (§12.1)
                did += ", pending rotation dropped"
            self._note(now, "applied", f"{shown}: {did}", UART2)
        elif isinstance(event, control.PositionFrame):
            self._position(event, now, shown)
        elif isinstance(event, control.SetSetting):
            self._set_setting(event, now, shown)
        elif isinstance(event, control.StoreFrame):
            self._store_op(event.op, now, shown)
        else:
            self._reads.append(event.read)
            self._note(
                now, "applied", f"{shown}: read {event.read.name}, reply in the next tick", UART2
            )

    def _position(self, frame: control.PositionFrame, now: float, shown: str) -> None:
        if self.drive_type.differential:
            self.uart2_errors += 1
            self._note(
                now, "rejected", f"{shown}: no position mode on a differential drive (§9.3)", UART2
            )
            return
        limit = self.params[params.BY_NAME["max_position"].index]
        move = tuple(_clamp(v, limit) for v in (frame.x, frame.y, frame.z))
        v = self.vehicle
        self._position_goal = (v.travel_x + move[0], v.travel_y + move[1], v.travel_z + move[2])
        self._command = frame
        self._note(now, "applied", f"{shown}: position, move by {move}", UART2)

    def _set_setting(self, frame: control.SetSetting, now: float, shown: str) -> None:
        setting = frame.setting
        if setting.param is None:
            self.gyro_calibration = frame.value
        elif setting.param in self.profile.settable:
            self._set_param(setting.param, frame.value)
        else:
            self._note(
                now,
                "rejected",
                f"{shown}: ignored: {setting.name} is not settable on this board",
                UART2,
            )
            return
        self._note(now, "applied", f"{shown}: {setting.name} = {frame.value}", UART2)

    def _store_op(self, op: settings.StoreOp, now: float, shown: str) -> None:
        if op.name == "save":
            self._save(now, shown, UART2)
            return
        if op.name == "load" and self.profile.saves:
            saved, warning = self.store.load()
            values = saved if saved is not None else self.profile.defaults
            did = "loaded the saved settings" if saved is not None else f"{warning}"
        else:
            values, did = self.profile.defaults, "loaded the factory defaults"
        self._load(values)
        self._note(now, "applied", f"{shown}: {did}", UART2)


def _clamp(value: float, limit: float) -> float:
    return max(-limit, min(limit, value))


def _duty(value: int, speed: float) -> float:
    """A differential drive's duty in 0.1 % as a speed: above 1000 counts as 1000 (§9.1)."""
    return math.copysign(min(abs(value), control.MAX_DUTY) / control.MAX_DUTY * speed, value)


def _int32(value: float) -> int:
    """A whole 32-bit signed value, saturating."""
    return max(-(2**31), min(2**31 - 1, round(value)))
