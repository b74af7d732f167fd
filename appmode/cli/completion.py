"""`appmode completion SHELL`: the shell's completion script (argcomplete), and what
answers the shell's questions when it asks (`complete`)."""

from __future__ import annotations

import argparse
import sys

from appmode.cli.commands import COMMANDS
from appmode.cli.options import Subparsers
from appmode.errors import AppmodeError, install_line

SHELLS = ("bash", "zsh", "fish")

INSTALL = {
    "bash": "echo 'eval \"$(appmode completion bash)\"' >> ~/.bashrc",
    "zsh": "echo 'eval \"$(appmode completion zsh)\"' >> ~/.zshrc",
    "fish": "appmode completion fish > ~/.config/fish/completions/appmode.fish",
}
"""The one command that installs completion for each shell (then open a new shell)."""

MISSING = f"shell completion needs argcomplete: {install_line('completion')}"


def register(sub: Subparsers) -> argparse.ArgumentParser:
    parser = sub.add_parser(
        "completion",
        help=COMMANDS["completion"],
        description="Print the completion script for SHELL (commands, options, their "
        "choices, files). Install it once with: "
        + "; ".join(f"{shell}: {command}" for shell, command in INSTALL.items()),
    )
    parser.add_argument("shell", choices=SHELLS, metavar="SHELL", help=", ".join(SHELLS))
    return parser


def complete(parser: argparse.ArgumentParser) -> None:
    """Answer the shell's completion request for `parser` and end the process; nothing
    when argcomplete is not installed (the shell then completes nothing)."""
    try:
        import argcomplete
    except ImportError:
        return
    argcomplete.autocomplete(parser)


def run(args: argparse.Namespace) -> int:
    try:
        from argcomplete import shell_integration
    except ImportError:
        raise AppmodeError(MISSING) from None
    sys.stdout.write(shell_integration.shellcode(["appmode"], shell=args.shell))
    return 0
