"""Board profiles (docs/design.md, "The board in parts"): every point where the simulated board can
behave differently, as one named switch, and one row of values per profile.

`sheet` is the vendor's sheet as docs/protocol.md §1–§12 reads it; `minibalance` is the
reference firmware as measured (§13). A third board is a third row.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, replace
from functools import cache
from types import MappingProxyType

from appmode.board.names import PROFILE_NAMES
from appmode.errors import AppmodeError
from appmode.files import read_limited
from appmode.protocol import layouts, params, profile_file
from appmode.protocol.chassis_profile import ChassisSpec
from appmode.protocol.directions import BUTTON_PAGE, MOTIONS, Motion
from appmode.protocol.layouts import SCALED, VELOCITY, Layout
from appmode.protocol.params import DriveType
from appmode.protocol.profile_file import ProfileError, ProfileFile


@dataclass(frozen=True, slots=True)
class Profile:
    """One board's behaviour, switch by switch (the §13 table, row by row)."""

    name: str
    # -- bytes in (§2)
    firmware_frames: bool
    """Frames as the reference loop reads them (§13): Q frames by position 3, set values
    summed byte by byte in float32, nothing validated. Else the sheet's checked grammar."""
    steer_in_frames: bool
    """Every byte inside a frame also goes through the direction logic of §2.1."""
    frame_restarts: bool
    """A `{` inside a frame starts a new frame (else it is kept as a byte of the frame)."""
    settable: frozenset[int]
    """The parameters a set frame changes; the others are ignored."""
    stall_speed: int
    """A max_speed from 1 to stall_speed − 1 becomes stall_speed at the next tick (0: never)."""
    # -- parameters (§5)
    saves: bool
    """`{Q:W}` writes the store, and power-up loads it."""
    defaults: tuple[int, ...]
    """The parameters at power-up when nothing is saved."""
    drive_types: bool
    """system_mode's drive type is kept and used (else the car is always omni/mecanum)."""
    c_saturates: bool
    """C record values printed as a 32-bit C `int` (saturating) rather than as held."""
    # -- motion (§4)
    buttons: Mapping[str, Motion]
    """The button page's letters; a letter not here stops."""
    numeric_buttons: bool
    """The bytes 0x01–0x08 act as letters on the button page (else they stop)."""
    sticky_rotation: bool
    """A rotation begun on the button page ends only with a direction or another button."""
    ramp: float | None
    """Units a held direction adds per 10 ms tick, up to ±max_speed; None: a first-order
    lag toward the target (vehicle.RESPONSE_TAU)."""
    coast: float
    """With no direction, x and y (and z on the button page) are divided by this each
    tick."""
    float32: bool
    """The car's velocity and the A record's scaling are the chip's 32-bit float
    arithmetic (§13.1), each result rounded as it is stored."""
    dead_time: float
    """Seconds after power-up with the motors off and the battery voltage read as 0."""
    # -- records (§3)
    a_layout: Layout
    """What the A record's fields hold."""
    truncate: bool
    """Whole numbers in records by truncation, as C casts do (else rounded)."""
    yaw_low: int
    """The yaw field runs from yaw_low to yaw_low + 359 (whole degrees)."""
    battery_floor: bool
    """The battery percentage never goes below 0."""
    # -- timing (§3.4)
    period_ms: int | None
    """Fixed milliseconds between records; None: the record's wire time rounded up to
    pause_step_ms, plus pause_ms."""
    pause_ms: int
    pause_step_ms: int
    byte_ms: float
    """A byte's wire time as the firmware's pause counts it."""
    first_record: str
    """"A" or "B": the first record after power-up."""
    read_lost_in_c: bool
    """A `{Q:P}` that arrives while a C record is going out is lost."""
    startup_text: bytes
    """What the APP port carries at power-up, before the first record."""
    startup_ms: int
    """When the start-up text goes out, in ms after power-up."""
    first_record_ms: int
    """When the first record goes out, in ms after power-up."""
    # -- the control port (§8–§12)
    takeover_byte: int
    """The byte received on UART2 at which UART2 takes over the motion (§8.3)."""
    control_modes: frozenset[int]
    """The frame modes UART2 obeys (01 velocity, 02 motors, 03 position, 80 settings and
    reads); frames of other modes are ignored and counted."""
    firmware_uart2: bool
    """UART2 as the reference loop runs it (§13.1): after `FF FE` the next 8 bytes are a
    frame, whatever they hold; the last frame is taken at a COPY_MS tick with no frame
    being received, once UART2 drives; a velocity frame sets the velocity as it is (no
    clamp, no lag), and until one does the motion freezes at the take-over; after each
    APP record UART2 carries what is left of the status the loop writes there. Else the
    sheet's frames (§8–§12)."""
    # -- a data profile (a profile file with no firmware model here)
    file: ProfileFile | None = None
    """The profile file whose records this board writes, with no physics: the speed is
    DATA_SPEED, the parameters are only stored, read and saved. None: sheet or
    minibalance, modelled."""

    def record_period_ms(self, size: int) -> int:
        """Milliseconds from a record of `size` bytes to the next (§3.4, §13)."""
        if self.period_ms is not None:
            return self.period_ms
        step = self.pause_step_ms
        return step * math.ceil(size * self.byte_ms / step - 1e-9) + self.pause_ms

    @property
    def answers_reads(self) -> bool:
        """UART2 takes settings frames: reads are answered, the encoder report exists."""
        from appmode.protocol.control import SETTINGS  # the codec, only when asked

        return SETTINGS in self.control_modes

    @property
    def velocity_si(self) -> tuple[float, float]:
        """What one velocity unit is: m/s of x and y, rad/s of z (its profile file's)."""
        return self.a_layout.profile.velocity_si

    @property
    def chassis(self) -> ChassisSpec | None:
        """A WHEELTEC board's chassis port, or None: the board has none."""
        return self.file.chassis if self.file is not None else None

    @property
    def fixed_drive(self) -> DriveType | None:
        """The drive type a host need not read: omni on a board without drive types."""
        return None if self.drive_types else DriveType.OMNI

    def check_uart2(self) -> Profile:
        """Itself, or AppmodeError when its firmware has no control port (a profile file
        that says so): a host must not send it `FF FE` frames."""
        if self.file is not None and not self.file.control_port:
            raise AppmodeError(
                f"the {self.name} profile has no control port (UART2): drive its APP port "
                "(leave out --uart2)"
            )
        return self

    def check(self, drive: bool, flash: bool) -> None:
        """AppmodeError when a board of this profile is asked for what it does not have."""
        if drive and not self.drive_types:
            raise AppmodeError(
                f"the {self.name} profile has no drive types (see appmode protocol 13): "
                "leave out the drive type"
            )
        if flash and self.file is not None:
            raise AppmodeError(
                f"the {self.name} profile's simulated board keeps what it saves in memory "
                "(it has no model of that firmware's flash): leave out the flash file"
            )
        if flash and not self.saves:
            raise AppmodeError(
                f"the {self.name} profile saves nothing and starts from its factory "
                "defaults (see appmode protocol 13): leave out the flash file"
            )


MPU_LINES = (
    "mpu_set_sensor complete ......",
    "mpu_set_sensor complete ......",
    "mpu_configure_fifo complete ......",
    "mpu_set_sample_rate complete ......",
    "dmp_load_motion_driver_firmware complete ......",
    "dmp_set_orientation complete ......",
    "dmp_enable_feature complete ......",
    "dmp_set_fifo_rate complete ......",
    "setting bias succesfully ......",
    "mpu_set_dmp_state complete ......",
)
"""The reference firmware's sensor start-up messages (§13.1), spelling as it prints them:
`mpu_set_sensor` twice, and no `mpu_dmp_init` line."""

SHEET = Profile(
    name="sheet",
    firmware_frames=False,
    steer_in_frames=False,
    frame_restarts=True,
    settable=frozenset(range(params.PARAM_COUNT)),
    stall_speed=0,
    saves=True,
    defaults=params.DEFAULTS,
    drive_types=True,
    c_saturates=False,
    buttons=BUTTON_PAGE,
    numeric_buttons=True,
    sticky_rotation=False,
    ramp=None,
    coast=1.0,
    float32=False,
    dead_time=0.0,
    a_layout=VELOCITY,
    truncate=False,
    yaw_low=-179,
    battery_floor=True,
    period_ms=50,
    pause_ms=0,
    pause_step_ms=5,
    byte_ms=1.04,
    first_record="A",
    read_lost_in_c=False,
    startup_text=b"",
    startup_ms=0,
    first_record_ms=0,
    takeover_byte=10,
    control_modes=frozenset({0x01, 0x02, 0x03, 0x80}),
    firmware_uart2=False,
)

MINIBALANCE = Profile(
    name="minibalance",
    firmware_frames=True,
    steer_in_frames=True,
    frame_restarts=False,
    settable=frozenset(range(7)),
    stall_speed=15,
    saves=False,
    defaults=(30, 3000, 40, 0, 40, 10, 10, 0, 0),
    drive_types=False,
    c_saturates=True,
    buttons=MappingProxyType(
        {
            k: MOTIONS[v]
            for k, v in (
                ("A", "forward"),
                ("C", "rotate-cw"),
                ("E", "backward"),
                ("G", "rotate-ccw"),
            )
        }
    ),
    numeric_buttons=False,
    sticky_rotation=True,
    ramp=0.5,
    coast=1.05,
    float32=True,
    dead_time=1.9,
    a_layout=SCALED,
    truncate=True,
    yaw_low=-180,
    battery_floor=False,
    period_ms=None,
    pause_ms=45,
    pause_step_ms=5,
    byte_ms=1.04,
    first_record="B",
    read_lost_in_c=True,
    startup_text=b"".join(line.encode() + b"\r\n" for line in MPU_LINES),
    startup_ms=500,
    first_record_ms=1400,
    takeover_byte=11,
    control_modes=frozenset({0x01}),
    firmware_uart2=True,
)

PROFILES: dict[str, Profile] = {p.name: p for p in (SHEET, MINIBALANCE)}
if tuple(PROFILES) != PROFILE_NAMES:
    raise AssertionError("board/names.py must name the profiles of board/profiles.py")


def from_file(file: ProfileFile) -> Profile:
    """A board for a profile file: the sheet's board with the family's byte-by-byte
    intake, its records and parameters as the file declares them, on its shortest
    period; no physics."""
    return replace(
        SHEET,
        name=file.name,
        firmware_frames=True,
        frame_restarts=False,
        settable=frozenset(i for i, p in enumerate(file.params) if p.maximum > p.minimum),
        saves=file.saves,
        defaults=tuple(p.default for p in file.params),
        drive_types=False,
        c_saturates=True,
        numeric_buttons=False,
        a_layout=layouts.Layout(file.name, file),
        truncate=True,
        period_ms=file.period_ms[0],
        byte_ms=10_000 / file.baud,
        control_modes=SHEET.control_modes if file.control_port else frozenset(),
        file=file,
    )


_USERS: dict[str, Profile] = {}
"""The users' profile files read in this run, by their name: a recording that names one
(with its digest) reads back with it."""


@cache
def profile_named(name: str) -> Profile:
    """The profile called `name` (a modelled one, a shipped profile file's, a user's file
    read before under that name, or a file at that path); AppmodeError says what is
    wrong, one line."""
    if name in PROFILES:
        return PROFILES[name]
    if name in _USERS:
        return _USERS[name]
    try:
        profile = from_file(load(name))
    except ProfileError as exc:
        raise AppmodeError(str(exc).replace("\n", "; ")) from None
    if profile.name not in profile_file.SHIPPED:
        _USERS[profile.name] = profile
    return profile


def digest(profile: Profile) -> str | None:
    """A user's profile file's digest (the first 16 hex digits of its text's SHA-256),
    which a recording keeps beside its name; None for what appmode ships."""
    if profile.file is None or profile.name in profile_file.SHIPPED:
        return None
    import hashlib  # only a user's file needs it: start-up stays short

    return hashlib.sha256(profile.file.text.encode()).hexdigest()[:16]


def board_line(profile: Profile, drive: str | None = None) -> tuple[str, ...]:
    """A recording's `@board` directive: the profile by name (a user's file by its digest
    too) and the drive type, as a replay needs them; none for the sheet's defaults."""
    words = [] if profile is SHEET else [f"profile={profile.name}"]
    made = digest(profile)
    words += [f"digest={made}"] if made else []
    words += [f"drive={drive}"] if drive else []
    return (f"board {' '.join(words)}",) if words else ()


def recorded_profile(name: str, recorded: str | None) -> Profile:
    """The profile a recording's `@board profile=NAME digest=…` names: a shipped one, or
    the user's file of that name and digest given in this run (--profile FILE)."""
    if recorded is None and name in profile_file.SHIPPED:
        return profile_named(name)
    user = _USERS.get(name)
    if user is None and recorded is None:
        raise AppmodeError(
            f"unknown board profile {name!r}: choose one of "
            f"{', '.join(profile_file.SHIPPED)}, or give its profile file with --profile FILE"
        )
    if user is None:
        raise AppmodeError(
            f"profile={name} is a profile file's (digest {recorded}): give that file with "
            "--profile FILE"
        )
    if recorded is not None and digest(user) != recorded:
        raise AppmodeError(
            f"profile={name} was recorded with a file of digest {recorded}, and the "
            f"{name} given has {digest(user)}: give the file it was recorded with (or "
            "change the digest in the @board line)"
        )
    return user


@cache
def load(source: str) -> ProfileFile:
    """A shipped profile file by name, or a user's file by path; ProfileError says what
    is wrong, a line a mistake."""
    if source in profile_file.SHIPPED:
        return profile_file.shipped(source)
    try:
        text = read_limited(source, profile_file.MAX_SIZE, "a profile is a few kB")
    except (OSError, UnicodeDecodeError) as exc:
        known = ", ".join(profile_file.SHIPPED)
        why = exc.strerror if isinstance(exc, OSError) and exc.strerror else str(exc)
        raise ProfileError(
            source, [f"cannot read it ({why}): give a file or one of {known}"]
        ) from None
    return profile_file.parse(text, source)
