"""The `appmode` command line: one module per command, collected into one parser."""

from __future__ import annotations

import argparse
import contextlib
import errno
import importlib
import os
import sys
from collections.abc import Callable, Sequence
from types import ModuleType

from appmode import __version__
from appmode.cli.commands import COMMANDS, EXAMPLES
from appmode.cli.options import Parser
from appmode.errors import AppmodeError
from appmode.host import signals

TYPE_CHECKING = False  # typing.TYPE_CHECKING without importing typing: start-up stays short
if TYPE_CHECKING:
    from appmode.cli.outlet import Outlet

OUTPUT_ERRORS = {errno.ENOSPC, errno.EDQUOT, errno.EFBIG, errno.EIO, errno.EBADF}
"""The errors of a write that did not go through (other OSErrors are reported as they are)."""

DRIVES = frozenset(
    {"drive", "web", "demo", "send", "params", "replay", "conform", "tap", "share", "ros"}
)
"""The commands that can move a car: their output goes through bounded writers
(`outlet`), so that no reader of it can hold up the stop."""
Handler = Callable[[argparse.Namespace], int]
BUG_STATUS = 70
"""The exit status of a bug in appmode (BSD's EX_SOFTWARE)."""
SHOW_TRACEBACK = "APPMODE_TRACEBACK"
"""Set in the environment, a bug prints its traceback (for a report), not one line."""


def build_parser(command: str | None = None) -> argparse.ArgumentParser:
    """The parser: with a `command`, its arguments (its module loaded); with "", none
    built, the commands listed from COMMANDS (the table, not a parser each: each
    ArgumentParser costs start-up); with None, every command's arguments."""
    parser = Parser(
        prog="appmode",
        description="Drive, emulate and test robot-car boards that speak the APP protocol "
        "(9600 bps: letters drive, {…} frames read and set parameters).",
    )
    parser.add_argument(
        "-V",
        "--version",
        action=_Version,
        nargs=0,
        help="print the version (and, run from a git checkout, its commit) and exit",
    )
    if command == "":
        parser.usage = "appmode [-h] [-V] COMMAND ..."
        parser.add_argument("command", metavar="COMMAND", help=argparse.SUPPRESS)
        parser.commands = COMMANDS
        return parser
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=Parser)
    sub.required = True
    for name in COMMANDS if command is None else (command,):
        module: ModuleType = importlib.import_module(f"appmode.cli.{name}")
        command_parser = module.register(sub)
        command_parser.set_defaults(handler=module.run)
        if isinstance(command_parser, Parser):
            command_parser.examples = EXAMPLES[name]
    return parser


class _Version(argparse.Action):
    """`--version`: appmode's version, and the commit when run from a git checkout (asked
    of git only then: start-up stays short)."""

    def __call__(self, parser: argparse.ArgumentParser, *args: object) -> None:
        commit = checkout_commit()
        sys.stdout.write(f"appmode {__version__}{f' ({commit})' if commit else ''}\n")
        parser.exit()


def checkout_commit() -> str | None:
    """`git describe --always --dirty` of the checkout appmode runs from, or None."""
    import subprocess  # here: only --version asks git, and start-up stays short
    from pathlib import Path

    root = Path(__file__).resolve().parents[2]
    if not (root / ".git").exists():
        return None
    try:
        done = subprocess.run(
            ["git", "-C", str(root), "describe", "--always", "--dirty"],
            capture_output=True,
            text=True,
            timeout=5,
            check=False,
        )
    except (OSError, subprocess.SubprocessError):
        return None
    if done.returncode != 0:
        return None
    return done.stdout.strip() or None


def unknown_command(word: str) -> str:
    """What to say of a command that is none: the nearest ones, if any are near."""
    import difflib

    near = difflib.get_close_matches(word, list(COMMANDS), n=2, cutoff=0.6)
    hint = f": did you mean {' or '.join(repr(n) for n in near)}?" if near else ""
    return f"unknown command {word!r}{hint} (appmode --help lists the commands)"


def command_in(argv: Sequence[str]) -> str:
    """The command `argv` names (its first word that is no option), or "" for none: only
    its module is loaded (`appmode --help` loads none)."""
    return next((word for word in argv if not word.startswith("-")), "")


def main(argv: Sequence[str] | None = None) -> int:
    if sys.stderr is None:  # started with stderr closed: errors go nowhere, not to a crash
        sys.stderr = open(os.devnull, "w")  # noqa: SIM115 - for the life of the process
    if sys.stdin is None:  # started with stdin closed: read it as empty
        sys.stdin = open(os.devnull)  # noqa: SIM115 - for the life of the process
    if sys.stdout is None:
        print(
            "appmode: error: standard output is closed: run it with output to a terminal, "
            "a file or a pipe",
            file=sys.stderr,
        )
        return 2
    if "_ARGCOMPLETE" in os.environ:  # the shell asks what to complete (appmode completion)
        from appmode.cli.completion import complete

        complete(build_parser(None))
    words = sys.argv[1:] if argv is None else argv
    command = command_in(words)
    if command and command not in COMMANDS:
        print(f"appmode: error: {unknown_command(command)}", file=sys.stderr)
        return 2
    parser = build_parser(command)
    if not words:  # as git and pip do: the commands, not an error
        parser.print_help()
        return 0
    signals.install()
    outlets: list[tuple[Outlet, Outlet] | None] = []
    try:
        status = _run(parser, words, outlets)
    finally:
        lost = None
        if outlets and outlets[0] is not None:
            from appmode.cli import outlet

            lost = outlet.finish(outlets[0])
        signals.finish()
    if lost is not None:
        with contextlib.suppress(OSError):
            print(f"appmode: error: {lost}", file=sys.stderr)
        return status or 2
    return status


def _run(
    parser: argparse.ArgumentParser,
    words: Sequence[str],
    outlets: list[tuple[Outlet, Outlet] | None],
) -> int:
    """Parse and run the command, every mistake as one line on stderr; its exit status.
    A command that can move a car writes through bounded writers from when it starts
    (put in `outlets`); its help and usage are written before it can."""
    try:
        try:
            args = parser.parse_args(words)
        except SystemExit as exc:
            if exc.code:  # a usage error: argparse has said what, on stderr
                raise
            args = argparse.Namespace(handler=lambda _: 0)  # --help or --version: printed
        if getattr(args, "command", None) in DRIVES:  # not after --help
            from appmode.cli import outlet

            outlets.append(outlet.install())
        handler: Handler = args.handler
        status = handler(args)
        sys.stdout.flush()  # here, where a full disk or a closed pipe can be reported
        return status
    except AppmodeError as exc:
        from appmode.text import shortened

        print(f"appmode: error: {shortened(str(exc))}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        return 130
    except BrokenPipeError:  # the reader left (`| head`): end quietly, as cat does
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 0
    except OSError as exc:  # a full disk, a lost terminal: never a traceback
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        what = "cannot write the output" if exc.errno in OUTPUT_ERRORS else "failed"
        with contextlib.suppress(OSError):
            print(f"appmode: error: {what}: {exc.strerror or exc}", file=sys.stderr)
        return 2
    except Exception as exc:  # a bug: one line that says so, the traceback on request
        report_bug(exc)
        return BUG_STATUS


def report_bug(exc: Exception) -> None:
    """Say on stderr, in a line, that appmode failed (what, where in its code) and how to
    get the traceback for a report; with SHOW_TRACEBACK set, print the traceback."""
    import traceback

    if os.environ.get(SHOW_TRACEBACK):
        traceback.print_exception(exc)
        return
    frames = traceback.extract_tb(exc.__traceback__)
    where = ""
    if frames:
        path = frames[-1].filename.replace("\\", "/")
        path = "appmode/" + path.rsplit("/appmode/", 1)[1] if "/appmode/" in path else path
        where = f" at {path}:{frames[-1].lineno}"
    what = " ".join(f"{type(exc).__name__}: {exc}".split())[:200]
    with contextlib.suppress(OSError):
        print(
            f"appmode: internal error: {what}{where}: a bug in appmode; run it again with "
            f"{SHOW_TRACEBACK}=1 for the traceback, and report it",
            file=sys.stderr,
        )


if __name__ == "__main__":
    sys.exit(main())
