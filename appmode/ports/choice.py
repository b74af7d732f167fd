"""Which board a command opens, decided once: the port it drives (the APP port, or the
control port with the APP port of the same board beside it), the board's profile and,
where it matters, its drive type. `choose` holds every rule of how URLs, `--uart2`,
`--profile` and `--drive` combine; hosts and sessions read the `BoardChoice`."""

from __future__ import annotations

import os
from dataclasses import dataclass
from itertools import count

from appmode.board.profiles import Profile, profile_named
from appmode.errors import AppmodeError
from appmode.line.wire import APP, UART2
from appmode.ports.target import Target
from appmode.protocol.params import DriveType

_SHARES = count(1)
"""Numbers the names that make two sim:// ports one simulated board, in this process."""


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


def choose(
    url: Target,
    url2: Target | None = None,
    *,
    uart2: bool = False,
    profile: str | None = None,
    drive: str | None = None,
) -> BoardChoice:
    """The board `url` names — driven over its control port with `uart2`, or at `url2`
    (the same board's control port, `url` then its APP port) — with the `profile` named
    (else a sim:// URL's, else the sheet) and the `drive` type given; AppmodeError says
    what does not fit together."""
    board = url.with_sim(profile=profile, drive=drive)
    chosen = profile_named(profile or board.profile or "sheet")
    if url2 is None and not uart2:
        if drive and not board.simulated:
            raise AppmodeError(
                "--drive on a real board's APP port: its drive type is part of "
                "system_mode (appmode params URL --set system_mode=N), or add --uart2"
            )
        return BoardChoice(board, chosen)
    chosen.check_uart2()
    fixed = DriveType.from_cli_name(drive) if drive else chosen.fixed_drive
    if url2 is None:
        return BoardChoice(board.for_uart2(), chosen, control=True, drive=fixed)
    app, control = board, url2.with_sim(profile=profile, drive=drive)
    if app.simulated and control.simulated:
        app, control = _one_board(app, control)
    return BoardChoice(control, chosen, control=True, app=app, drive=fixed)


def _one_board(app: Target, uart2: Target) -> tuple[Target, Target]:
    """Two sim:// targets as the two ports of one simulated board (its options given on
    the first, or the same on both)."""
    app_options, uart2_options = (
        {k: v for k, v in t.sim.items() if k not in ("port", "share")} for t in (app, uart2)
    )
    if uart2_options and uart2_options != app_options:
        raise AppmodeError(
            f"{app} and {uart2} are one simulated board: give its options once, on "
            f"the first URL (appmode drive '{uart2}' sim://)"
        )
    return both_ports(app)


def both_ports(target: Target) -> tuple[Target, Target]:
    """A sim:// target's board opened on both its ports: (the APP port, UART2), one board
    (a name it shares, made here unless it names one)."""
    if "share" not in target.sim:
        target = target.with_sim(share=f"board-{os.getpid()}-{next(_SHARES)}")
    app = target if "port" not in target.sim else target.on_port(APP)
    return app, target.on_port(UART2)
