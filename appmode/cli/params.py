"""`appmode params`: read, set (verified) and save the nine parameters."""

from __future__ import annotations

import argparse
import json
import sys
from contextlib import ExitStack
from typing import TextIO

from appmode.cli.hostio import open_host
from appmode.cli.options import Subparsers, add_record, add_url
from appmode.errors import AppmodeError
from appmode.protocol import params
from appmode.protocol.render import params_table


def register(sub: Subparsers) -> argparse.ArgumentParser:
    prm = sub.add_parser(
        "params",
        help="read, set (verified) and save the nine parameters",
        description="Read the nine parameters; with --set, set each and verify it by reading "
        "back; with --save, save them to the board's flash. Names: "
        + ", ".join(p.name for p in params.PARAMS)
        + " (or their numbers 0-8).",
    )
    add_url(prm)
    prm.add_argument(
        "--set",
        action="append",
        default=[],
        metavar="NAME=VALUE",
        help="set a parameter (repeatable), e.g. --set max_speed=800",
    )
    prm.add_argument("--save", action="store_true", help="save to flash ({Q:W})")
    prm.add_argument("--json", action="store_true", help="print one JSON object")
    add_record(prm)
    return prm


def run(args: argparse.Namespace) -> int:
    return run_params(
        args.url, args.set, save=args.save, as_json=args.json, record=args.record, out=sys.stdout
    )


def parse_assignment(text: str) -> tuple[int, int]:
    """`NAME=VALUE` (or `N=VALUE`), checked against the parameter table."""
    name, sep, value = text.partition("=")
    if not sep:
        raise AppmodeError(f"--set {text!r}: expected NAME=VALUE, e.g. max_speed=800")
    param = params.lookup(name.strip())
    number = params.whole(value)
    if number is None:
        raise AppmodeError(
            f"--set {text!r}: {param.name} takes a whole number in {param.range_text}"
        )
    params.check_value(param.index, number)
    return param.index, number


def run_params(
    url: str, assignments: list[str], *, save: bool, as_json: bool, record: str | None, out: TextIO
) -> int:
    """Read the parameters; set each (verified by reading back), save, and print them."""
    changes = [parse_assignment(text) for text in assignments]  # all checked first
    with ExitStack() as stack:
        host = open_host(stack, url, record)
        values = host.read_params()
        for index, value in changes:
            values = host.set_param(index, value)
            print(f"set {params.PARAMS[index].name} = {value} (verified)", file=sys.stderr)
        if save:
            host.save()
            values = host.read_params()
            print(
                "sent {Q:W}: the board saves its parameters to flash (it sends no reply)",
                file=sys.stderr,
            )
    if as_json:
        out.write(
            json.dumps({p.name: v for p, v in zip(params.PARAMS, values, strict=True)}) + "\n"
        )
    else:
        out.write(params_table(values) + "\n")
    for index, value in enumerate(values):
        error = params.value_error(index, value)
        if error is not None:  # a board may hold it: say so, and how to repair it
            name = params.PARAMS[index].name
            print(
                f"appmode: the board holds {name} = {value} ({error}): repair it with "
                f"--set {name}=N",
                file=sys.stderr,
            )
    return 0
