"""`appmode profile`: the firmware profiles appmode ships, one shown whole, a user's file
checked."""

from __future__ import annotations

import argparse
import sys

from appmode.board.profiles import load
from appmode.cli.commands import COMMANDS
from appmode.cli.options import Subparsers, profiles_offered
from appmode.protocol import param_values
from appmode.protocol.profile_file import SHIPPED, Field, ProfileError, ProfileFile
from appmode.text import escaped


def register(sub: Subparsers) -> argparse.ArgumentParser:
    profile = sub.add_parser(
        "profile",
        help=COMMANDS["profile"],
        description="A profile says what a firmware of the family sends and takes on its "
        "APP port: its records' fields, its parameters with their ranges and scales, its "
        "pages. appmode ships sheet, minibalance and balance; --profile PATH reads your "
        "own (write one with 'appmode profile show' of the nearest as a start).",
    )
    actions = profile.add_subparsers(dest="action", metavar="ACTION", required=True)
    actions.add_parser("list", help="the shipped profiles, one a line")
    show = actions.add_parser("show", help="one profile: its records, parameters and pages")
    name = show.add_argument("name", metavar="NAME|PATH", help="a shipped profile or a file")
    name.completer = profiles_offered  # type: ignore[attr-defined]  # argcomplete's
    show.add_argument("--toml", action="store_true", help="print its file as it is")
    layout = actions.add_parser(
        "layout",
        help="a Foxglove layout for one profile (JSON: in Foxglove or Lichtblick, Layouts → "
        "Import from file)",
    )
    named = layout.add_argument("name", metavar="NAME|PATH", help="a shipped profile or a file")
    named.completer = profiles_offered  # type: ignore[attr-defined]  # argcomplete's
    check = actions.add_parser("check", help="check a profile file: one line a mistake")
    path = check.add_argument("path", metavar="FILE", help="the profile file (TOML)")
    path.completer = profiles_offered  # type: ignore[attr-defined]  # argcomplete's
    return profile


def run(args: argparse.Namespace) -> int:
    if args.action == "list":
        width = max(len(name) for name in SHIPPED)
        for name in SHIPPED:
            print(f"{name:<{width}}  {load(name).description}")
        return 0
    if args.action == "check":
        try:
            profile = load(args.path)
        except ProfileError as exc:
            print(exc, file=sys.stderr)
            return 2  # as every error: one line a mistake
        fields = len(profile.a) + len(profile.b)
        print(f"{args.path}: profile {profile.name}: {fields} record fields, "
              f"{len(profile.params)} parameters: fine")  # fmt: skip
        return 0
    if args.action == "layout":
        return _layout(args.name)
    try:
        profile = load(args.name)
    except ProfileError as exc:
        print(exc, file=sys.stderr)
        return 2
    if args.toml:
        sys.stdout.write(profile.text)
        return 0
    sys.stdout.write(shown(profile))
    return 0


def _layout(name: str) -> int:
    """The Foxglove layout of profile `name`, as JSON on stdout."""
    import json

    from appmode.board.profiles import profile_named
    from appmode.viewers.layout import foxglove_layout

    made = foxglove_layout(profile_named(name).a_layout)
    sys.stdout.write(json.dumps(made, indent=2, ensure_ascii=False) + "\n")
    return 0


def shown(profile: ProfileFile) -> str:
    """A profile for people: what it is, its records, its parameters."""
    low, high = profile.period_ms
    period = f"{low} ms" if low == high else f"{low}–{high} ms"
    pages = ", ".join(f"{letter} {page}" for letter, page in profile.pages.items()) or "none"
    lines = [
        f"{profile.name}: {profile.description}",
        f"  source: {profile.source}",
        f"  APP port at {profile.baud} bps, a record every {period}; "
        f"{'{Q:W} saves' if profile.saves else '{Q:W} saves nothing'}; "
        f"{'a control port (UART2)' if profile.control_port else 'no control port'}",
        f"  pages: {pages}" + (f"; also sends {' '.join(profile.replies)}" * bool(profile.replies)),
        f"  the speed keys (+, −) change: {_speed(profile)}",
        "",
    ]
    for kind, fields in (("A", profile.a), ("B", profile.b)):
        lines.append(f"{kind} record:")
        lines += [f"  {_field(i, field)}" for i, field in enumerate(fields)]
    lines.append("parameters (your value × scale is the frame's: {n:v} sets n, {C…}$ reads all):")
    lines.append(f"   n  {'name':<18}  {'range':<24}  {'default':>10}  scale")
    for i, p in enumerate(profile.params):
        scale = (
            "" if p.scale == 1 else f"×{p.scale:g}: {p.name} 0.42 is {{{i}:{0.42 * p.scale:.0f}}}"
        )
        span, default = param_values.range_text(p), param_values.to_user(p, p.default)
        lines.append(f"  {i:2d}  {p.name:<18}  {span:<24}  {default:>10}  {scale}")
    return "".join(escaped(line) + "\n" for line in lines)  # a file's texts, as they are


def _speed(profile: ProfileFile) -> str:
    if profile.speed_param:
        return profile.speed_param
    if profile.speed_keys:
        keys = ", ".join(f"{k} {v:+d}" for k, v in profile.speed_keys.items())
        return f"the speed, with its own letters ({keys})"
    return "nothing (no speed parameter)"


def _field(index: int, field: Field) -> str:
    what = [field.unit] if field.unit else []
    if field.scale != 1:
        what.append(f"×{field.scale:g}")
    if not field.signed:
        what.append("magnitude")
    if field.wrap:
        what.append(f"wraps at {field.wrap}")
    if field.motion:
        what.append("grows with the speed")
    if field.battery:
        what.append("battery")
    return f"{index}  {field.name:<16}  {field.label:<16}  {', '.join(what)}"
