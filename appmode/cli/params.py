"""`appmode params`: read, set (verified) and save the nine parameters."""

from __future__ import annotations

import argparse
import sys
from contextlib import ExitStack

from appmode.cli.commands import COMMANDS
from appmode.cli.options import (
    HOLDS,
    Subparsers,
    add_profile,
    add_record,
    add_uart2,
    add_url,
    board_choice,
)
from appmode.errors import AppmodeError
from appmode.protocol import param_values, params
from appmode.protocol.param_values import Specs

TYPE_CHECKING = False  # typing.TYPE_CHECKING without importing typing: start-up stays short
if TYPE_CHECKING:  # imported when the command runs: start-up stays short
    from typing import TextIO

    from appmode.ports.choice import BoardChoice


def register(sub: Subparsers) -> argparse.ArgumentParser:
    prm = sub.add_parser(
        "params",
        help=COMMANDS["params"],
        description="Read the nine parameters; with --set, set each and verify it by reading "
        "back; with --save, save them to the board's flash. Names: "
        + ", ".join(p.name for p in params.PARAMS)
        + " (or their numbers 0-8). Each table numbers its values as its port does: n is "
        "the index of the APP port's {n:value} frame (0-8), and with --uart2 SS is the "
        "setting's byte in the control port's FF FE 80 80 SS frame (1-10).",
    )
    add_url(prm)
    prm.add_argument(
        "--set",
        action="append",
        default=[],
        metavar="NAME=VALUE",
        help="set a parameter (repeatable), e.g. --set max_speed=800",
    )
    saving = prm.add_mutually_exclusive_group()
    saving.add_argument(
        "--save",
        action="store_true",
        help="ask the board to save to flash ({Q:W}); it does not confirm, so appmode "
        "remembers what was saved for --verify-saved",
    )
    saving.add_argument(
        "--load",
        action="store_true",
        help="with --uart2: load the saved settings into the running copy first",
    )
    saving.add_argument(
        "--defaults",
        action="store_true",
        help="with --uart2: load the factory defaults into the running copy first",
    )
    saving.add_argument(
        "--verify-saved",
        action="store_true",
        help="after the board restarted: check it holds what --save saved (exit 1 if not)",
    )
    prm.add_argument("--json", action="store_true", help="print one JSON object")
    add_uart2(
        prm,
        "the ten settings over the board's control port (binary frames at 115200 bps; "
        "--save, --load, --defaults as its load/save frames)",
    )
    add_profile(
        prm,
        f"the board's profile (with a sim:// URL, the simulated board's), for the names, "
        f"ranges, scales and defaults shown, {HOLDS}",
        default=None,
    )
    add_record(prm)
    return prm


def run(args: argparse.Namespace) -> int:
    from appmode.line.wire import APP, UART2

    choice = board_choice(args)
    return {APP: _on_app, UART2: _on_control}[choice.port](choice, args)


def _on_control(choice: BoardChoice, args: argparse.Namespace) -> int:
    if args.verify_saved:
        raise AppmodeError(
            "--verify-saved is for the APP port: over --uart2, restart the board and "
            "read the settings again"
        )
    from appmode.cli import uart2

    store = next((op for op in ("load", "defaults", "save") if getattr(args, op)), None)
    return uart2.run_params(
        choice, args.set, store=store, as_json=args.json, record=args.record, out=sys.stdout
    )


def _on_app(choice: BoardChoice, args: argparse.Namespace) -> int:
    if args.load or args.defaults:
        raise AppmodeError("--load and --defaults are frames of the control port: add --uart2")
    return run_params(
        choice,
        args.set,
        save=args.save,
        verify=args.verify_saved,
        as_json=args.json,
        record=args.record,
        out=sys.stdout,
    )


def parse_assignment(text: str, specs: Specs = param_values.SHEET) -> tuple[int, int]:
    """`NAME=VALUE` (or `N=VALUE`), in the user's units, checked against the profile's
    table: (index, the frame's integer)."""
    name, sep, value = text.partition("=")
    if not sep:
        example = f"{specs[0].name}={param_values.to_user(specs[0], specs[0].default)}"
        raise AppmodeError(f"--set {text!r}: expected NAME=VALUE, e.g. {example}")
    index = param_values.lookup(specs, name.strip())
    try:
        number = param_values.from_user(specs[index], value)
    except AppmodeError as exc:
        raise AppmodeError(f"--set {text!r}: {exc}") from None
    param_values.check(specs, index, number)
    return index, number


def run_params(
    choice: BoardChoice,
    assignments: list[str],
    *,
    save: bool,
    as_json: bool,
    record: str | None,
    out: TextIO,
    verify: bool = False,
) -> int:
    """Read the parameters; set each (verified by reading back), save, and print them;
    or check them against what was saved (`verify`)."""
    import json

    from appmode.cli.hostio import open_host
    from appmode.host import saves
    from appmode.protocol.render import params_table

    url, profile = choice.target, choice.profile
    specs = profile.a_layout.params
    changes = [parse_assignment(text, specs) for text in assignments]  # all checked first
    saved = saves.recall(url.url) if verify else None
    if verify and saved is None:
        raise AppmodeError(
            f"no save of {url} to check: appmode remembers the saves made with "
            f"'appmode params {url} --save' (in {saves.path()})"
        )
    with ExitStack() as stack:
        host = open_host(stack, choice, record)
        values = host.read_params()
        for index, value in changes:
            values = host.set_param(index, value)
            shown = param_values.to_user(specs[index], value)
            print(f"set {specs[index].name} = {shown} (verified)", file=sys.stderr)
        if save:
            host.save()
            values = host.read_params()
            print(
                f"save requested ({{Q:W}}); the board does not confirm a save: restart it, "
                f"then run appmode params {url} --verify-saved",
                file=sys.stderr,
            )
            try:
                saves.remember(url.url, values)
            except AppmodeError as exc:  # the set and the save went out all the same
                print(
                    f"appmode: WARNING: {exc}: --verify-saved will not know this save",
                    file=sys.stderr,
                )
    status = 0
    if saved is not None:
        status = _verify(specs, values, *saved)
    if as_json:
        pairs = zip(specs, values, strict=True)
        out.write(json.dumps({s.name: param_values.user_number(s, v) for s, v in pairs}) + "\n")
    else:
        out.write(params_table(values, profile.defaults, specs) + "\n")
    for index, value in enumerate(values):
        error = param_values.error(specs, index, value)
        if error is not None:  # a board may hold it: say so, and how to repair it
            name = specs[index].name
            print(
                f"appmode: the board holds {name} = {value} ({error}): repair it with "
                f"--set {name}=N",
                file=sys.stderr,
            )
    return status


def _verify(specs: Specs, values: tuple[int, ...], saved: tuple[int, ...], at: str) -> int:
    """Say whether the board holds what was saved; 1 if it does not."""
    differ = [
        f"{spec.name} {param_values.to_user(spec, a)} → {param_values.to_user(spec, b)}"
        for spec, a, b in zip(specs, saved, values, strict=False)
        if a != b
    ]
    if not differ:
        print(f"the board holds the parameters saved at {at}: the save held", file=sys.stderr)
        return 0
    print(
        f"appmode: the board does not hold what was saved at {at}: {', '.join(differ)} "
        "(not restarted since, or the save did not take)",
        file=sys.stderr,
    )
    return 1
