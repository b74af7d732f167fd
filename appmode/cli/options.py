"""Arguments that several commands share."""

from __future__ import annotations

import argparse
import os
import sys
from argparse import HelpFormatter
from collections.abc import Callable
from functools import partial

from appmode.errors import AppmodeError
from appmode.text import wrapped

TYPE_CHECKING = False  # typing.TYPE_CHECKING without importing typing: start-up stays short
if TYPE_CHECKING:  # the rest is imported where it is used
    from typing import Any, NoReturn, TypeAlias

    from _typeshed import SupportsWrite

    from appmode.ports.choice import BoardChoice
    from appmode.ports.target import Target

URL_FORMS = (
    "the board: /dev/ttyUSB0, /dev/rfcomm0, COM3 (?baud=N), socket://HOST:PORT, "
    "rfc2217://HOST:PORT, ble://ADDRESS or NAME (a BLE module), bt://ADDRESS (a paired "
    "classic module), loop:// or sim:// (the simulated board)"
)


DAY = 86400.0
"""The longest wait any command takes: longer is surely a typing error."""


def target(text: str) -> Target:
    """An argument that names a board: parsed once into the Target every layer reads."""
    from appmode.ports.target import parse_target

    return parse_target(text)


def add_url(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("url", metavar="URL", type=target, help=URL_FORMS)


Address = tuple[str, int]
"""Where a server listens: (host, port), parsed once from `[HOST:]PORT` (`listen`)."""


def listen(option: str) -> Callable[[str], Address]:
    """The type of an option that names where a server listens, `[HOST:]PORT`
    (`ports.endpoints.parse_listen`: host 127.0.0.1 unless given)."""

    def address(text: str) -> Address:
        from appmode.ports.endpoints import parse_listen

        return parse_listen(text, option)

    return address


def add_car(parser: argparse.ArgumentParser) -> None:
    """URL, the car (its APP port), and URL2, its control port: what `share` and `ros`
    serve."""
    parser.add_argument("url", type=target, metavar="URL", help="the car (its APP port)")
    parser.add_argument(
        "url2", nargs="?", type=target, metavar="URL2", help="the same car's control port"
    )


def add_uart2(parser: argparse.ArgumentParser, what: str) -> None:
    parser.add_argument(
        "--uart2",
        action="store_true",
        help=f"{what}; a sim:// URL opens the simulated board's control port",
    )


def add_chassis(parser: argparse.ArgumentParser, what: str) -> None:
    parser.add_argument(
        "--chassis",
        action="store_true",
        help=f"{what}: a WHEELTEC ROS car's chassis port (7B … 7D frames at 115200 bps; "
        "--profile wheeltec-mec by default); a sim:// URL opens the simulated board's",
    )


def file_name(text: str) -> str:
    """A file argument: an empty one would be taken for none, and nothing written."""
    if not text.strip():
        raise argparse.ArgumentTypeError("an empty file name: name a file")
    return text


def add_record(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "--record",
        type=file_name,
        metavar="FILE",
        help="record the session as a transcript (flushed line by line)",
    )


SHIPPED_PROFILES = (
    "sheet",
    "minibalance",
    "balance",
    "wheeltec-mec",
    "wheeltec-akm",
    "wheeltec-diff",
)
"""The profiles appmode ships (profile_file.SHIPPED, which checks it): named here so the
command line offers them without loading them."""
HOLDS = (
    "for what its records hold: sheet (x, y, z), minibalance (|0.7x|, |0.7y|, battery; "
    "see appmode protocol 13), balance (the two-wheel balance car), wheeltec-mec, "
    "wheeltec-akm, wheeltec-diff (WHEELTEC's ROS cars: their chassis port, --chassis), or "
    "a profile FILE of your own (appmode profile show sheet --toml writes one to start from)"
)
A_RECORD = f"the board's profile, {HOLDS}"
ON_A_BOARD = f"the board's profile (with a sim:// URL, the simulated board's), {HOLDS}"
"""--profile of a command that opens a board (`board_choice`)."""
FROM_URL = "a sim:// URL's profile, else sheet"


def add_admission(parser: argparse.ArgumentParser) -> None:
    """`--allow ADDRESS` and `--secure`: which phones an advertised module takes."""

    def address(text: str) -> str:
        from appmode.bluetooth.advertise.admission import addresses

        try:
            return addresses(text)
        except ValueError as exc:
            raise argparse.ArgumentTypeError(str(exc)) from None

    parser.add_argument(
        "--allow",
        action="append",
        type=address,
        metavar="ADDRESS",
        help="with an advertised module: take only this phone (its Bluetooth address; "
        "again for more); any other's writes and links are refused",
    )
    parser.add_argument(
        "--secure",
        action="store_true",
        help="with an advertised module: take only phones paired (bonded) with this "
        "machine; BlueZ asks the phone to pair before its first write",
    )


def add_profile(
    parser: argparse.ArgumentParser,
    what: str = A_RECORD,
    default: str | None = "sheet",
    unset: str = FROM_URL,
) -> None:
    """`--profile NAME`; with `default` None it is None when not given (`unset` says what
    then applies)."""
    action = parser.add_argument(
        "--profile",
        type=profile_name,
        metavar="NAME|FILE",
        default=default,
        help=f"{what} (default: {default or unset})",
    )
    action.completer = profiles_offered  # type: ignore[attr-defined]  # argcomplete's


def profiles_offered(prefix: str, **_: object) -> list[str]:
    """What `--profile <Tab>` offers (argcomplete): the shipped profiles, then profile
    files (`.toml`) and folders."""
    from argcomplete.completers import FilesCompleter

    names = [name for name in SHIPPED_PROFILES if name.startswith(prefix)]
    return names + list(FilesCompleter(allowednames=("toml",))(prefix))


def profile_name(text: str) -> str:
    """A shipped profile's name, or a profile file that reads (one line when not)."""
    if text in SHIPPED_PROFILES:
        return text
    from appmode.board.profiles import load
    from appmode.protocol.profile_file import ProfileError

    try:
        load(text)
    except ProfileError as exc:
        raise argparse.ArgumentTypeError(str(exc).replace("\n", "; ")) from None
    return text


def endpoint(text: str) -> str:
    """A Zenoh endpoint to connect to, `tcp/HOST:PORT` or `tls/HOST:PORT`, checked once."""
    return _endpoint(text, listening=False)


def listening_endpoint(text: str) -> str:
    """A Zenoh endpoint to listen on (port 0: a free one), checked once."""
    return _endpoint(text, listening=True)


def _endpoint(text: str, listening: bool) -> str:
    """`text` checked; AppmodeError (one line, as a bad URL's) if it is no endpoint."""
    from appmode.ports.remote import BadRemote, check_endpoint

    try:
        return check_endpoint(text, listening=listening)
    except BadRemote as exc:
        raise AppmodeError(str(exc)) from None


def host_id(text: str) -> str:
    """A car's host's id (`id=` in the URL appmode share printed), checked once."""
    from appmode.ports.remote import HOST_ID

    if not HOST_ID.fullmatch(text):
        raise AppmodeError(
            f"{text[:60]!r} is no host id: copy the id= part of the URL appmode share printed"
        )
    return text


def add_host_id(parser: argparse.ArgumentParser, option: str = "--id") -> None:
    parser.add_argument(
        option,
        dest="host_id",
        type=host_id,
        metavar="ID",
        help="the cars' hosts' id, the id= part of the URL appmode share printed: only what "
        "they sign is heard (default: the first host met with this key, then kept)",
    )


def board_choice(
    args: argparse.Namespace, *, url: Target | None = None, both: bool = False
) -> BoardChoice:
    """The board a command's arguments name, decided once (`ports.choice.choose`, the one
    way in): its URL (or `url`, a car the user chose another way); the same board's
    control port (a second URL, `--uart2-url`, or `--uart2` for the URL's own);
    `--profile`; `--drive`; `both` of its ports where one URL reaches them."""
    from appmode.errors import AppmodeError
    from appmode.ports.choice import choose

    url2, uart2_url = getattr(args, "url2", None), getattr(args, "uart2_url", None)
    if url2 is not None and uart2_url is not None:
        raise AppmodeError("give the control port once: a second URL or --uart2-url")
    return choose(
        url or args.url,
        url2 or uart2_url,
        uart2=getattr(args, "uart2", False),
        profile=getattr(args, "profile", None),
        drive=getattr(args, "drive_type", None),
        both=both,
        chassis=getattr(args, "chassis", False),
    )


NAN = float("nan")
"""What a number that is none reads as (math.nan, without importing math: start-up)."""


def terminal_columns() -> int:
    """The terminal's width as `shutil.get_terminal_size` finds it: $COLUMNS, else
    standard output's terminal, else 80."""
    try:
        columns = int(os.environ.get("COLUMNS", ""))
    except ValueError:
        columns = 0
    if columns > 0:
        return columns
    try:
        return os.get_terminal_size(sys.__stdout__.fileno()).columns or 80  # type: ignore[union-attr]
    except (AttributeError, ValueError, OSError):
        return 80


class Parser(argparse.ArgumentParser):
    """An argument parser that takes options only as spelled: no prefix matching, so a
    mistyped option is an error naming it, never another option."""

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        kwargs.setdefault("allow_abbrev", False)
        # told the terminal's width: argparse would ask shutil, whose import (bz2, lzma,
        # zlib) was a twentieth of a command's start-up
        kwargs.setdefault("formatter_class", partial(HelpFormatter, width=terminal_columns() - 2))
        super().__init__(*args, **kwargs)
        self.examples: tuple[str, ...] = ()
        """Command lines shown at the end of the help."""
        self.commands: dict[str, str] = {}
        """Commands listed in the help by name and help (the top parser's: none built)."""

    def format_help(self) -> str:
        """argparse's help, with the commands listed, then the examples as typed."""
        help = super().format_help()
        if self.commands:  # as argparse lists a subparser's choices
            indent = " " * (max(map(len, self.commands)) + 7)
            listed = "".join(
                wrapped(f"    {name:<{len(indent) - 4}}{text}", terminal_columns() - 2, indent)
                + "\n"
                for name, text in self.commands.items()
            )
            help = help.replace("\noptions:", f"\ncommands:\n{listed}\noptions:", 1)
        shown = "".join(f"  $ {example}\n" for example in self.examples)
        return help + (f"\nexamples:\n{shown}" if shown else "")

    def error(self, message: str) -> NoReturn:
        """argparse's, with a long word of the message (a 10 kB URL) cut short."""
        from appmode.text import shortened

        super().error(shortened(message))

    def print_help(self, file: SupportsWrite[str] | None = None) -> None:
        """As argparse's, but a write that fails (a full disk, a closed pipe) is not passed
        over: the command line reports it (help is output too)."""
        (file or sys.stdout).write(self.format_help())

    def print_usage(self, file: SupportsWrite[str] | None = None) -> None:
        (file or sys.stdout).write(self.format_usage())

    def exit(self, status: int = 0, message: str | None = None) -> NoReturn:
        if message:
            sys.stderr.write(message)
        sys.exit(status)


if TYPE_CHECKING:
    Subparsers: TypeAlias = "argparse._SubParsersAction[argparse.ArgumentParser]"
else:  # a name the commands import; their annotations are never evaluated
    Subparsers = "argparse._SubParsersAction[argparse.ArgumentParser]"
"""What `add_subparsers()` returns."""


def number_type(
    low: float, high: float, *, whole: bool = False, low_open: bool = False
) -> Callable[[str], float]:
    """An argparse type: a finite number in [low, high] (or (low, high] with `low_open`),
    written in ASCII; anything else is refused with the range, so nothing can hang on
    `inf`, `nan` or a speed of 1e-308."""

    def parse(text: str) -> float:
        try:
            value = float(text) if text.isascii() else NAN
        except ValueError:
            value = NAN
        inside = (low < value if low_open else low <= value) and value <= high
        if not inside or (whole and value != int(value)):
            kind = "a whole number" if whole else "a number"
            left = "(" if low_open else "["
            span = f"{left}{low:,.10g}, {high:,.10g}]"
            raise argparse.ArgumentTypeError(f"{text!r} is not {kind} in {span}")
        return int(value) if whole else value

    return parse
