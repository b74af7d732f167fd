"""The board's control port, UART2 (§8–§12, §13.1): binary frames in — velocities, motor
speeds, positions, settings, reads — and replies and encoder reports out; APP bytes
while APP mode is on; the take-over of the motion at the profile's byte."""

from __future__ import annotations

from typing import cast

from appmode.board import kinematics
from appmode.board.app_port import AppPort
from appmode.board.core import UART2, Core
from appmode.board.intake import ControlIntake
from appmode.protocol import control, control_decoders, params, settings
from appmode.protocol.params import DriveType

REPORT_MS = 50
"""The encoder report's period on UART2 (§12)."""
APP_MODE, ENCODER_REPORT = params.MODE_BIT["app_mode"], params.MODE_BIT["encoder_report"]
"""system_mode's bits that say where records go and whether UART2 reports (§12)."""


class ControlPort:
    """What the board makes of UART2's bytes, and what it sends there each tick."""

    def __init__(self, core: Core, app_port: AppPort) -> None:
        self.core = core
        self.app_port = app_port
        self.received = 0
        """Bytes received on UART2 (the take-over counts them)."""
        self._frames = control_decoders.FrameDecoder(core.drive_type)
        self._intake = ControlIntake()
        self._last_frame: bytes | None = None  # the last frame, not yet taken (§13.1)
        self._reports = core.profile.answers_reads
        self._report_for: tuple[object, ...] | None = None  # what _report_is was made of
        self._report_is = b""

    def receive(self, data: bytes, now: float) -> None:
        """Apply bytes that arrived on the control port at `now` (§8)."""
        core = self.core
        before = self.received
        self.received += len(data)
        if core.mode("app_mode"):
            self.app_port.receive(data, now, UART2)
        elif core.profile.firmware_uart2:
            for frame in self._intake.feed(data):
                self._last_frame = frame
        else:
            drive = core.drive_type  # a mode-02 frame's length depends on it
            if self._frames.drive is not drive:
                self._frames.drive = drive
            for event in self._frames.feed(data):
                self._apply(cast(control.HostEvent, event), now)
        at = core.profile.takeover_byte
        if not core.uart2_control and before < at <= self.received:
            core.uart2_control = True
            core.direction, core.turn = 0, 0
            core.note(
                now,
                "info",
                f"UART2 takes over the motion at its byte {at}; the APP port's direction "
                "is dropped and its drive letters are ignored from now on (§8.3)",
                UART2,
            )

    def take_frame(self, now: float) -> None:
        """A COPY_MS tick of the reference loop (§13.1): once UART2 drives, its last frame
        is taken, if none is being received; only a velocity frame moves the car."""
        core = self.core
        frame = self._last_frame
        if frame is None or not core.uart2_control or self._intake.receiving:
            return
        self._last_frame = None
        shown = frame.hex(" ").upper()
        mode = frame[2]
        if mode not in core.profile.control_modes:
            name = control.MODES.get(mode, f"mode {mode:02X}")
            core.note(now, "rejected", f"{shown}: {name} frame: no effect (§13.1)", UART2)
            return
        event = control_decoders.FrameDecoder().feed(frame)[0]
        assert isinstance(event, control.VelocityFrame), "control_modes holds only 01 here"
        core.command = event
        core.note(now, "applied", f"{shown}: velocity {event.values}, as it is (§13.1)", UART2)

    def tick(self) -> None:
        """What UART2 sends in a control tick: the replies to reads received since the
        last tick (§11), and the encoder report every REPORT_MS while bit 6 is set (§12)."""
        core = self.core
        if core.reads:
            for read in core.reads:
                value = self._read_value(read)
                core.out2 += control.encode(control.Reply(read.reply_id, value))
            core.reads.clear()
        if core.tick_ms % REPORT_MS == 0 and self._reports:
            mode = core.system_mode
            if mode & ENCODER_REPORT and not mode & APP_MODE:
                core.out2 += self._report(mode)

    def _report(self, mode: int) -> bytes:
        """The encoder report's bytes; made again only when what it shows changed (a car
        driving steadily reports the same wheels 20 times a second)."""
        core, v = self.core, self.core.vehicle
        key = (mode, core.target_velocity, v.vx, v.vy, v.vz, core.command, core.uart2_control)
        if key != self._report_for:
            self._report_for = key
            targets = self._encoders(self._wheel_targets())
            self._report_is = control.encode_report(targets, self._encoders(self._wheels()))
        return self._report_is

    def angle_mode(self, frame: control.VelocityFrame) -> bool:
        return frame.angle and self.core.drive_type is not DriveType.DIFF_GYRO

    # ------------------------------------------------------------ frames

    def _apply(self, event: control.HostEvent, now: float) -> None:
        """One event of UART2's binary stream (§9–§11)."""
        core = self.core
        shown = event.raw.hex(" ").upper()
        if isinstance(event, (control.Garbage, control.BadFrame)):
            self._reject(now, f"{shown}: {event.reason}")
            return
        mode = event.raw[2]
        if mode not in core.profile.control_modes:
            self._reject(
                now,
                f"{shown}: ignored: the {core.profile.name} board has no "
                f"{control.MODES[mode]} frames on UART2 (§13)",
            )
            return
        if isinstance(event, (control.VelocityFrame, control.MotorFrame)):
            core.command, core.position_goal = event, None
            did = f"{control.MODES[mode]} {event.values}"
            if isinstance(event, control.VelocityFrame) and self.angle_mode(event):
                core.pending_angle += event.c
                did += f", angle mode: {core.pending_angle / 10:g}° pending"
            elif event.raw == control.STOP and core.pending_angle:
                core.pending_angle = 0.0  # the stop frame stops a rotation too (§12.1)
                did += ", pending rotation dropped"
            core.note(now, "applied", f"{shown}: {did}", UART2)
        elif isinstance(event, control.PositionFrame):
            self._position(event, now, shown)
        elif isinstance(event, control.SetSetting):
            self._set_setting(event, now, shown)
        elif isinstance(event, control.StoreFrame):
            self._store_op(event.op, now, shown)
        else:
            core.reads.append(event.read)
            core.note(
                now, "applied", f"{shown}: read {event.read.name}, reply in the next tick", UART2
            )

    def _reject(self, now: float, text: str) -> None:
        self.core.uart2_errors += 1
        self.core.note(now, "rejected", text, UART2)

    def _position(self, frame: control.PositionFrame, now: float, shown: str) -> None:
        core = self.core
        if core.drive_type.differential:
            self._reject(now, f"{shown}: no position mode on a differential drive (§9.3)")
            return
        limit = core.params[params.BY_NAME["max_position"].index]
        move = tuple(clamp(v, limit) for v in (frame.x, frame.y, frame.z))
        v = core.vehicle
        core.position_goal = (v.travel_x + move[0], v.travel_y + move[1], v.travel_z + move[2])
        core.command = frame
        core.note(now, "applied", f"{shown}: position, move by {move}", UART2)

    def _set_setting(self, frame: control.SetSetting, now: float, shown: str) -> None:
        core = self.core
        setting = frame.setting
        if setting.param is None:
            core.gyro_calibration = frame.value
        elif setting.param in core.profile.settable:
            core.params[setting.param] = frame.value
        else:
            core.note(
                now,
                "rejected",
                f"{shown}: ignored: {setting.name} is not settable on this board",
                UART2,
            )
            return
        core.note(now, "applied", f"{shown}: {setting.name} = {frame.value}", UART2)

    def _store_op(self, op: settings.StoreOp, now: float, shown: str) -> None:
        core = self.core
        if op.name == "save":
            core.save(now, shown, UART2)
            return
        if op.name == "load" and core.profile.saves:
            saved, warning = core.store.load()
            values = saved if saved is not None else core.profile.defaults
            did = "loaded the saved settings" if saved is not None else f"{warning}"
        else:
            values, did = core.profile.defaults, "loaded the factory defaults"
        self._load(values)
        core.note(now, "applied", f"{shown}: {did}", UART2)

    def _load(self, values: tuple[int, ...] | tuple[float, ...]) -> None:
        """Load settings into the running copy; system_mode's unsaved bits stay (§10)."""
        core = self.core
        mode = int(core.params[params.SYSTEM_MODE]) & params.UNSAVED_MASK
        core.params = [float(v) for v in values[: params.PARAM_COUNT]]
        core.params[params.SYSTEM_MODE] = int(core.params[params.SYSTEM_MODE]) | mode
        core.gyro_calibration = int(values[params.PARAM_COUNT]) if len(values) > 9 else 0

    # ------------------------------------------------------------ wheels

    def _wheel_targets(self) -> tuple[float, ...]:
        """What each wheel is driven at: a motor frame's speeds while UART2 drives by
        one, else the wheels of the body's target velocity."""
        core = self.core
        command = core.command
        if isinstance(command, control.MotorFrame) and core.uart2_control:
            return motor_speeds(command, core.drive_type)
        return kinematics.wheels(core.drive_type, *core.target_velocity)

    def _wheels(self) -> tuple[float, ...]:
        v = self.core.vehicle
        return kinematics.wheels(self.core.drive_type, v.vx, v.vy, v.vz)

    def _encoders(self, values: tuple[float, ...]) -> tuple[int, ...]:
        """Wheel values as the encoders give them: whole, signed by encoder_reverse."""
        core = self.core
        sign = -1 if core.mode("encoder_reverse") else 1
        count = control.motor_count(core.drive_type)
        return tuple([int32(sign * value) for value in (values + (0.0,) * count)[:count]])

    def _read_value(self, read: settings.Read) -> int:
        """The value a read's reply carries (§11)."""
        core = self.core
        setting = settings.BY_NAME.get(read.name)
        if setting is not None:
            held = core.gyro_calibration if setting.param is None else core.params[setting.param]
            return int(held) & params.U32
        if read.ss == settings.PENDING_ANGLE:
            return int32(core.pending_angle)
        v = core.vehicle
        if read.ss >= settings.POSITION_BASE:
            wheels = kinematics.wheels(core.drive_type, v.travel_x, v.travel_y, v.travel_z)
            index = read.ss - settings.POSITION_BASE
        else:
            wheels = self._wheels()
            index = read.ss - settings.SPEED_BASE
        encoders = self._encoders(wheels)
        return encoders[index] if index < len(encoders) else 0  # no wheel D on an omni


def motor_speeds(frame: control.MotorFrame, drive: DriveType) -> tuple[float, ...]:
    """A motor frame's speeds for the motors of `drive`: a frame taken before the drive
    type changed (§10) drives a motor it did not name at 0, and names one too many
    (wheel D on an omni) for nothing (§9.2)."""
    count = control.motor_count(drive)
    return tuple(map(float, (frame.speeds + (0,) * count)[:count]))


def clamp(value: float, limit: float) -> float:
    return max(-limit, min(limit, value))


def int32(value: float) -> int:
    """A whole 32-bit signed value, saturating."""
    return max(-(2**31), min(2**31 - 1, round(value)))
