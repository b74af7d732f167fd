"""The board's firmware as a deterministic state machine with an injected clock.

`Board.receive(data, now)` applies host bytes at `now`; `Board.poll(now)` returns the
telemetry due by `now`; the control port (§8–§12) and a WHEELTEC board's chassis port
(§15) have their own pairs, with the same clock and state. Time only moves forward. The
control loop runs in ticks of TICK seconds from boot; records go out on the profile's
schedule (§3.4, §13), on a millisecond grid: the same inputs at the same times give the
same bytes, whatever the pattern of `poll` calls. A profile differs by its switches.

`Board` is the front and the clock, and runs the control loop; its parts share one
`Core`: `telemetry` (the records' schedule), `app_port` (UART3, and UART2 in APP mode),
`control_port` (UART2's frames, replies and reports) and `chassis_port` (§15).
"""

from __future__ import annotations

import math
from collections import deque

from appmode.board import kinematics
from appmode.board.app_port import AppPort
from appmode.board.chassis_port import ChassisPort
from appmode.board.chip import float32
from appmode.board.control_port import (
    APP_MODE,
    ENCODER_REPORT,
    REPORT_MS,
    ControlPort,
    clamp,
    motor_speeds,
)
from appmode.board.core import UART3, Core, Note
from appmode.board.profiles import SHEET, Profile
from appmode.board.store import MemoryStore, Store
from appmode.board.telemetry import Telemetry
from appmode.board.vehicle import Vehicle
from appmode.protocol import control, params
from appmode.protocol.directions import Page, motion_for, target_velocity
from appmode.protocol.params import DriveType

TICK = 0.01
TICK_MS = 10
SLOT = 0.05
"""The sheet profile's time between records."""
MAX_CATCH_UP = 200
"""Ticks run one by one when the board falls behind; beyond that it skips ahead."""
MAX_RAMP = 2000
"""Ticks of a ramp run when the board skips ahead (20 s: any ramp has settled)."""
POSITION_GAIN = 2.0
"""Position mode drives each axis at this many times its remaining distance a second
(at most max_speed): the car slows as it nears the target and holds it (§9.3)."""
ANGLE_SPEED = 0.5
"""Angle mode turns at this fraction of max_speed (§9.1)."""
COPY_MS = 5
"""How often the reference loop takes UART2's last frame (§13.1)."""


class Board:
    """The firmware: pages, directions, parameters, telemetry schedule, flash."""

    def __init__(
        self,
        store: Store | None = None,
        *,
        drive: DriveType | None = None,
        now: float = 0.0,
        centivolts: float | None = None,
        profile: Profile = SHEET,
    ) -> None:
        self.core = core = Core(profile, store if store is not None else MemoryStore(), drive, now)
        if centivolts is not None:
            core.vehicle.centivolts = centivolts
        self.telemetry = Telemetry(core)
        self.app_port = AppPort(core, self.telemetry)
        self.control_port = ControlPort(core, self.app_port)
        self.chassis_port = ChassisPort(core, profile.chassis)
        self._copy_ms = 0.0 if profile.firmware_uart2 else math.inf  # the next COPY_MS tick
        self._target_for: tuple[object, ...] | None = None  # what _target was worked out for
        self._target_is: tuple[float, float, float] = (0.0, 0.0, 0.0)  # and what it was
        self._velocity_for: tuple[object, ...] | None = None  # a velocity frame's, the same
        self._velocity_is: tuple[float, float, float] = (0.0, 0.0, 0.0)

    # ------------------------------------------------------------ what others read

    @property
    def profile(self) -> Profile:
        return self.core.profile

    @property
    def store(self) -> Store:
        return self.core.store

    @property
    def params(self) -> list[float]:
        return self.core.params

    @property
    def gyro_calibration(self) -> int:
        return self.core.gyro_calibration

    @property
    def vehicle(self) -> Vehicle:
        return self.core.vehicle

    @property
    def page(self) -> Page:
        return self.core.page

    @property
    def direction(self) -> int:
        return self.core.direction

    @property
    def turn(self) -> int:
        return self.core.turn

    @property
    def errors(self) -> int:
        return self.core.errors

    @property
    def warnings(self) -> int:
        return self.core.warnings

    @property
    def notes(self) -> deque[Note]:
        return self.core.notes

    @property
    def uart2_control(self) -> bool:
        return self.core.uart2_control

    @property
    def uart2_errors(self) -> int:
        return self.core.uart2_errors

    @property
    def pending_angle(self) -> float:
        return self.core.pending_angle

    @property
    def drive_type(self) -> DriveType:
        return self.core.drive_type

    @property
    def _c_on_wire_until(self) -> float:
        return self.telemetry.c_on_wire_until

    # ------------------------------------------------------------ clock

    def next_slot(self) -> float:
        """When the board next sends something: a record, a reply, an encoder report."""
        return min(self.next_sends())

    def next_sends(self) -> tuple[float, float, float]:
        """When the board next sends on UART3, on UART2 and on its chassis port (infinity:
        nothing planned). Records go out on UART3, or on UART2 in APP mode (§12);
        replies and encoder reports on UART2; status frames on the chassis port (§15)."""
        core, telemetry = self.core, self.telemetry
        uart3, uart2 = float(telemetry.record_ms), telemetry.burst_ms
        mode = core.system_mode
        if mode & APP_MODE:
            uart3, uart2 = uart2, uart3
        if core.reads:
            uart2 = min(uart2, core.tick_ms)
        elif mode & ENCODER_REPORT and not mode & APP_MODE:
            uart2 = min(uart2, -(-core.tick_ms // REPORT_MS) * REPORT_MS)
        status = self.chassis_port.status_ms / 1000
        return core.boot + uart3 / 1000, core.boot + uart2 / 1000, core.boot + status

    def next_reply(self) -> float:
        """When the board next answers a read on UART2 (infinity when none is pending)."""
        core = self.core
        return core.boot + core.tick_ms / 1000 if core.reads else math.inf

    def advance(self, now: float) -> None:
        """Run every tick and record due by `now`."""
        core, telemetry = self.core, self.telemetry
        due = math.floor((now - core.boot) * 1000 + 1e-6)
        behind = (due - core.tick_ms) // TICK_MS
        if behind > MAX_CATCH_UP:
            skipped = behind - MAX_CATCH_UP
            self._control(skipped, at_once=True)
            core.tick_ms += skipped * TICK_MS
            if telemetry.record_ms < core.tick_ms:
                period = core.profile.period_ms or TICK_MS
                late = core.tick_ms - telemetry.record_ms
                telemetry.record_ms += -(-late // period) * period
            self._copy_ms = max(self._copy_ms, core.tick_ms)
            self.chassis_port.skip(core.tick_ms)
        chassis = self.chassis_port
        while (at := self._next_event()) <= due:
            if self._copy_ms == at:  # before the control tick of the same millisecond
                self.control_port.take_frame(core.boot + at / 1000)
                self._copy_ms += COPY_MS
            elif telemetry.burst_ms == at:
                telemetry.send_burst()
            elif core.tick_ms == at:
                if core.tick_ms and not core.reads and self._steps(due):
                    continue  # this tick and those after it, in one go
                if core.tick_ms:
                    self._control(1)
                self.control_port.tick()
                core.tick_ms += TICK_MS
                if not self._rest(due):
                    self._steps(due)
            elif chassis.status_ms == at:
                chassis.send_status()
            else:
                telemetry.send_record()

    def _next_event(self) -> float:
        """When, in ms from boot, the next tick, record, copy, burst or status frame is."""
        core, telemetry = self.core, self.telemetry
        times = (core.tick_ms, telemetry.record_ms, self._copy_ms, telemetry.burst_ms)
        return min(*times, self.chassis_port.status_ms)

    def _rest(self, due: int) -> bool:
        """Run at once the control ticks up to the next other event (by `due`) while the
        car rests and stays at rest: all such a tick does is drain the battery (exact:
        Vehicle.rest drains it tick by tick). An idle car costs no 100 Hz step. Whether
        it ran any."""
        core = self.core
        vehicle = core.vehicle
        if (
            vehicle.vx
            or vehicle.vy
            or vehicle.vz
            or any(core.target_velocity)
            or core.uart2_control
            or core.reads
            or core.mode("encoder_report")
            or self.chassis_port.drives()
        ):
            return False
        last = self._last_tick(due)
        if last < core.tick_ms or core.powered(core.tick_ms) != core.powered(int(last)):
            return False  # no tick before the next event, or the motors' power comes on
        ticks = int(last - core.tick_ms) // TICK_MS + 1
        vehicle.rest(ticks, TICK)
        core.tick_ms += ticks * TICK_MS
        return True

    def _last_tick(self, due: int) -> float:
        """The last millisecond (by `due`) at which a control tick comes before every other
        event: a record of the same millisecond comes after its tick, a copy or a burst
        before."""
        telemetry = self.telemetry
        last = min(due, telemetry.record_ms, self._copy_ms - 1, telemetry.burst_ms - 1)
        return self.chassis_port.last_tick(last)

    def _steps(self, due: int) -> bool:
        """Run at once the control ticks up to the next other event (by `due`) on a board
        whose ticks only step the car (it does not ramp), each exactly as alone, an
        encoder report's tick last (it reports after it; the caller answers reads at a
        tick of its own). A driving car costs one call per record, not five. Whether it
        ran any."""
        core = self.core
        profile = core.profile
        if profile.ramp is not None or profile.firmware_uart2:
            return False
        last = self._last_tick(due)
        if core.mode("encoder_report"):
            last = min(last, -(-core.tick_ms // REPORT_MS) * REPORT_MS)
        if last < core.tick_ms:
            return False
        ticks = int(last - core.tick_ms) // TICK_MS + 1
        self._control(ticks)
        core.tick_ms += (ticks - 1) * TICK_MS
        self.control_port.tick()  # the last tick's: the encoder report, if one is due
        core.tick_ms += TICK_MS
        return True

    # ------------------------------------------------------------ I/O-free edges

    def receive(self, data: bytes, now: float) -> None:
        """Apply host bytes that arrived at `now`."""
        self.advance(now)
        self.app_port.receive(data, now, UART3)

    def poll(self, now: float) -> bytes:
        """The telemetry bytes due by `now`."""
        self.advance(now)
        return _taken(self.core.out3)

    def receive_uart2(self, data: bytes, now: float) -> None:
        """Apply bytes that arrived on the control port at `now` (§8)."""
        self.advance(now)
        self.control_port.receive(data, now)

    def poll_uart2(self, now: float) -> bytes:
        """The control port's bytes due by `now`: replies, encoder reports, and records
        while APP mode is on."""
        self.advance(now)
        return _taken(self.core.out2)

    def poll_ports(self, now: float) -> tuple[bytes, bytes, bytes]:
        """What `poll` and `poll_uart2` give, and the chassis port's status frames, in one
        run of the board."""
        self.advance(now)
        return _taken(self.core.out3), _taken(self.core.out2), _taken(self.chassis_port.out)

    def receive_chassis(self, data: bytes, now: float) -> None:
        """Apply bytes that arrived on the chassis port at `now` (§15)."""
        self.advance(now)
        self.chassis_port.receive(data, now)

    def take_notes(self) -> list[Note]:
        notes = list(self.core.notes)
        self.core.notes.clear()
        return notes

    # ------------------------------------------------------------ the control loop

    def _control(self, ticks: int, *, at_once: bool = False) -> None:
        """`ticks` control ticks of TICK seconds; `at_once` (catching up after a stall):
        the APP port's direction moves the car in one step of them all."""
        core = self.core
        profile, vehicle = core.profile, core.vehicle
        speed = core.max_speed
        if 0 < speed < profile.stall_speed:
            core.params[params.MAX_SPEED] = speed = float(profile.stall_speed)
        if self.chassis_port.drive(ticks, TICK, at_once):
            return
        if core.uart2_control and profile.firmware_uart2:
            self._drive_firmware_uart2(ticks)
            return
        if core.uart2_control and not core.mode("app_mode"):
            self._drive_uart2(speed, min(ticks, MAX_RAMP))  # beyond, the car has settled
            return
        if profile.ramp is None:
            core.target_velocity = target = self._target(speed)
            if at_once:
                vehicle.step(target, ticks * TICK)
            else:
                vehicle.step(target, TICK, ticks)
        else:
            pushes = self._pushes() if core.powered(core.tick_ms) else (0, 0, 0)
            rounding = float32 if profile.float32 else float
            for _ in range(min(ticks, MAX_RAMP)):  # beyond that a ramp has long settled
                vehicle.ramp(pushes, speed, profile.ramp, profile.coast, TICK, rounding)
            core.target_velocity = (vehicle.vx, vehicle.vy, vehicle.vz)

    def _drive_firmware_uart2(self, ticks: int) -> None:
        """Control ticks as the reference loop runs them once UART2 drives (§13.1): the
        last velocity frame taken sets the velocity as it is; with none the car keeps
        the velocity it had at the take-over."""
        core = self.core
        command, vehicle = core.command, core.vehicle
        if isinstance(command, control.VelocityFrame):
            vehicle.vx, vehicle.vy, vehicle.vz = map(float, command.values)
        core.target_velocity = (vehicle.vx, vehicle.vy, vehicle.vz)
        vehicle.step(core.target_velocity, ticks * TICK)

    def _drive_uart2(self, speed: float, ticks: int) -> None:
        """`ticks` control ticks with UART2 in control: its last motion frame, angle
        mode's pending rotation, position mode's goal (§9)."""
        core = self.core
        vehicle = core.vehicle
        for tick in range(ticks):
            core.target_velocity = target = self._uart2_target(speed)
            if not core.pending_angle and core.position_goal is None:
                vehicle.step(target, TICK, ticks - tick)  # the target holds
                return
            vehicle.step(target, TICK)
            if core.pending_angle:
                left = core.pending_angle - vehicle.vz * vehicle.yaw_gain * TICK * 10
                core.pending_angle = left if left * core.pending_angle > 0 else 0.0

    def _uart2_target(self, speed: float) -> tuple[float, float, float]:
        """The velocity UART2 asks for this tick."""
        core = self.core
        command, vehicle = core.command, core.vehicle
        x = y = z = 0.0
        if isinstance(command, control.VelocityFrame):
            # worked out again only when what it depends on changed (100 times a second)
            key = (command, speed, core.system_mode)
            if key != self._velocity_for:
                self._velocity_for = key
                self._velocity_is = self._velocity_target(command, speed)
            x, y, z = self._velocity_is
        elif isinstance(command, control.MotorFrame):
            x, y, z = kinematics.body(core.drive_type, motor_speeds(command, core.drive_type))
        elif core.position_goal is not None:
            travel = (vehicle.travel_x, vehicle.travel_y, vehicle.travel_z)
            x, y, z = (
                clamp((goal - done) * POSITION_GAIN, speed)
                for goal, done in zip(core.position_goal, travel, strict=True)
            )
        if core.pending_angle:
            z = math.copysign(speed * ANGLE_SPEED, core.pending_angle)
        return (x, y, z)

    def _velocity_target(
        self, frame: control.VelocityFrame, speed: float
    ) -> tuple[float, float, float]:
        """A velocity frame's body velocity on this drive type (§9.1)."""
        a, b, c = frame.values
        if self.control_port.angle_mode(frame):
            c = 0
        drive = self.core.drive_type
        if drive is DriveType.DIFF_GYRO:
            left, right = _duty(a, speed), _duty(b, speed)
            return (0.0, (left + right) / 2, (left - right) / 2)
        if drive.differential:
            return (0.0, _duty(b, speed), _duty(c, speed))
        return (clamp(a, speed), clamp(b, speed), clamp(c, speed))

    def _target(self, speed: float) -> tuple[float, float, float]:
        """The velocity the APP port's direction asks for; worked out again only when
        what it depends on changed (it is asked 100 times a second)."""
        core = self.core
        key = (core.page, core.direction, speed, core.system_mode)
        if key != self._target_for:
            self._target_for = key
            if core.mode("motor_reverse"):
                speed = -speed
            differential = core.drive_type.differential
            self._target_is = target_velocity(
                core.page, core.direction, speed, differential, core.profile.buttons
            )
        return self._target_is

    def _pushes(self) -> tuple[int | None, ...]:
        """Which way a ramping board pushes x, y, z this tick (vehicle.ramp): with no
        direction x and y coast, and z too on the sheet's button page; a rotation that
        ended stops at once on the direction page (§13.1) and, where rotations are held
        apart (sticky_rotation), on the button page too: there every byte but C and G
        clears the rotation and z is 0 at the next tick (§13.2)."""
        core = self.core
        motion = motion_for(core.page, core.direction, core.profile.buttons)
        stops_at_once = core.page is Page.DIRECTION or core.profile.sticky_rotation
        z: int | None = core.turn or (0 if stops_at_once else None)
        if motion is None:
            return (None, None, z)
        x, y, turn = (int(math.copysign(1, f)) if f else 0 for f in motion.holonomic)
        return (x, y, turn or z)


def _taken(out: bytearray) -> bytes:
    """What a port has to send, which it no longer holds."""
    data = bytes(out)
    out.clear()
    return data


def _duty(value: int, speed: float) -> float:
    """A differential drive's duty in 0.1 % as a speed: above 1000 counts as 1000 (§9.1)."""
    return math.copysign(min(abs(value), control.MAX_DUTY) / control.MAX_DUTY * speed, value)
