"""Which board a command opens, decided once: the port it drives (the APP port, the
control port with the APP port of the same board beside it, or a WHEELTEC board's
chassis port), the board's profile and, where it matters, its drive type. `choose` holds
every rule of how URLs, `--uart2`, `--chassis`, `--profile` and `--drive` combine; hosts
and sessions read the `BoardChoice`, and every command its ports (`ports()`, `app_port`,
`control_port`): none chooses again."""

from __future__ import annotations

from dataclasses import dataclass

from appmode.board.profiles import Profile, profile_named
from appmode.errors import AppmodeError
from appmode.line.wire import APP, CHASSIS, UART2
from appmode.ports.target import Target, board_ports
from appmode.protocol.params import DriveType


@dataclass(frozen=True, slots=True)
class BoardChoice:
    """A board as a command opens it."""

    target: Target
    """The port that is driven: the APP port, or with `control` the control port."""
    profile: Profile
    """The board's firmware: what its records hold, what stops it, what UART2 takes."""
    control: bool = False
    """Driven over the control port (UART2, binary frames)."""
    app: Target | None = None
    """With `control`: the same board's APP port, opened beside it (its records shown)."""
    drive: DriveType | None = None
    """The car's drive type when given or fixed by the profile (else read from the board)."""
    chassis: bool = False
    """Driven over a WHEELTEC board's chassis port (`7B … 7D` frames), alone."""

    @property
    def known_drive(self) -> DriveType | None:
        """The drive type known before the board is read: given, fixed by the profile, or
        the simulated board's (omni unless its URL says); None for a board to be read."""
        if self.drive is not None or not self.target.simulated:
            return self.drive
        return DriveType.from_cli_name(self.target.sim_drive or "omni")

    @property
    def port(self) -> str:
        """The port driven, by name (`app`, `uart2`, `chassis`): the key of a command's
        table of what it does on each port."""
        return CHASSIS if self.chassis else UART2 if self.control else APP

    @property
    def app_port(self) -> Target | None:
        """The board's APP port, when it is opened (driven, or beside the control port)."""
        if self.chassis:
            return None
        return self.app if self.control else self.target

    @property
    def control_port(self) -> Target | None:
        """The board's control port, when it is driven."""
        return self.target if self.control else None

    def ports(self) -> dict[str, Target]:
        """The board's ports this choice opens, by name, the APP port first."""
        found = {
            APP: self.app_port,
            UART2: self.control_port,
            CHASSIS: self.target if self.chassis else None,
        }
        return {name: target for name, target in found.items() if target is not None}


def choose(
    url: Target,
    url2: Target | None = None,
    *,
    uart2: bool = False,
    profile: str | None = None,
    drive: str | None = None,
    both: bool = False,
    chassis: bool = False,
) -> BoardChoice:
    """The board `url` names — driven over its control port with `uart2`, or at `url2`
    (the same board's control port, `url` then its APP port) — with the `profile` named
    (else a sim:// URL's, else the sheet) and the `drive` type given; AppmodeError says
    what does not fit together. With `both`, a URL that reaches both of a board's ports
    (a simulated board that has a control port; a shared car with `uart2`) opens both,
    its control port driven. With `chassis` (or a sim:// URL's `port=chassis`), the
    board's chassis port alone."""
    chassis = chassis or url.sim_port == CHASSIS
    paired = None
    ports: tuple[Target, Target | None, bool]
    if chassis:
        ports = (_chassis_port(url, url2, uart2=uart2, profile=profile, drive=drive), None, False)
    else:
        ports = board_ports(url, url2, uart2=uart2, profile=profile, drive=drive)
        if both and url2 is None and (url.simulated or (uart2 and url.remote is not None)):
            paired = board_ports(url, url.for_uart2(), uart2=False, profile=profile, drive=drive)
    default = "wheeltec-mec" if chassis else "sheet"
    chosen = profile_named(profile or ports[0].profile or default)
    if chassis:
        if chosen.chassis is None:
            raise AppmodeError(
                f"the {chosen.name} profile has no chassis port: give --profile "
                "wheeltec-mec, wheeltec-akm, wheeltec-diff, or a profile file with a "
                "[chassis] table"
            )
        return BoardChoice(ports[0], chosen, chassis=True)
    if paired is not None and (chosen.file is None or chosen.file.control_port):
        ports = paired  # both ports where the profile's board has a control port
    driven, beside, control = ports
    if not control:
        if drive and not driven.simulated:
            raise AppmodeError(
                "--drive on a real board's APP port: its drive type is part of "
                "system_mode (appmode params URL --set system_mode=N), or add --uart2"
            )
        return BoardChoice(driven, chosen)
    chosen.check_uart2()
    fixed = DriveType.from_cli_name(drive) if drive else chosen.fixed_drive
    return BoardChoice(driven, chosen, control=True, app=beside, drive=fixed)


def _chassis_port(
    url: Target, url2: Target | None, *, uart2: bool, profile: str | None, drive: str | None
) -> Target:
    """The chassis port of the board `url` names, with a WHEELTEC profile (by default
    wheeltec-mec: a host sends what it is asked, and the car does what its kind can)."""
    if uart2 or url2 is not None:
        raise AppmodeError(
            "--chassis drives a WHEELTEC board's chassis port alone: leave out --uart2 "
            "and a second URL"
        )
    if drive:
        raise AppmodeError(
            "--drive is the control port's drive type: a chassis's kind is its profile's "
            "(--profile wheeltec-mec, wheeltec-akm or wheeltec-diff)"
        )
    board = url.with_sim(profile=profile or url.profile or "wheeltec-mec")
    if board.simulated or board.remote is not None:
        if board.sim_port not in (APP, CHASSIS) or (
            "port" in board.options and board.sim_port != CHASSIS
        ):
            raise AppmodeError(
                f"{board} names the board's {board.sim_port} port: --chassis drives its "
                "chassis port (port=chassis, or leave port= out)"
            )
        board = board.on_port(CHASSIS)
    return board
