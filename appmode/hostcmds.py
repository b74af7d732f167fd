"""`appmode send`, `params` and `monitor`: scriptable host commands over any URL."""

from __future__ import annotations

import json
import sys
from contextlib import ExitStack, closing
from typing import TextIO

from . import params
from .client import LinkStatus
from .errors import AppmodeError
from .host import Event, Host
from .protocol import HostDecoder
from .query import QueryDone, QueryFailed
from .render import describe, line, params_table, to_json
from .simport import sim_directives
from .tokens import Wait, parse_token
from .transcript import Recorder


def _open_host(stack: ExitStack, url: str, record: str | None) -> Host:
    recorder = (
        stack.enter_context(closing(Recorder.create(record, 0.0, sim_directives(url))))
        if record
        else None
    )
    return stack.enter_context(Host(url, tap=recorder))


def _show(host: Host, event: Event, out: TextIO, as_json: bool) -> None:
    if isinstance(event, LinkStatus):
        print(f"appmode: {event.text}", file=sys.stderr, flush=True)
        return
    if isinstance(event, (QueryDone, QueryFailed)):
        return
    if as_json:
        out.write(json.dumps({"t": round(host.now(), 3), **to_json(event)}) + "\n")
    else:
        out.write(line(host.now(), "<", event.raw, describe(event)) + "\n")
    out.flush()


def run_send(
    url: str,
    tokens: list[str],
    *,
    listen: float,
    raw: bool,
    as_json: bool,
    record: str | None,
    out: TextIO,
) -> int:
    """Send the tokens in order, printing what comes back; `Z` is always sent last."""
    steps = [parse_token(token, raw) for token in tokens]  # all checked before sending
    with ExitStack() as stack:
        host = _open_host(stack, url, record)
        for step in steps:
            if isinstance(step, Wait):
                for event in host.events(step.seconds):
                    _show(host, event, out, as_json)
                continue
            host.send(step)
            if not as_json:
                text = ", ".join(describe(e) for e in HostDecoder().feed(step))
                out.write(line(host.now(), ">", step, text) + "\n")
            for event in host.poll(0):
                _show(host, event, out, as_json)
        for event in host.events(listen):
            _show(host, event, out, as_json)
    return 0


def parse_assignment(text: str) -> tuple[int, int]:
    """`NAME=VALUE` (or `N=VALUE`), checked against the parameter table."""
    name, sep, value = text.partition("=")
    if not sep:
        raise AppmodeError(f"--set {text!r}: expected NAME=VALUE, e.g. max_speed=800")
    param = params.lookup(name.strip())
    if not value.strip().isdigit():
        raise AppmodeError(
            f"--set {text!r}: {param.name} takes a whole number in {param.range_text}"
        )
    params.check_value(param.index, int(value))
    return param.index, int(value)


def run_params(
    url: str, assignments: list[str], *, save: bool, as_json: bool, record: str | None, out: TextIO
) -> int:
    """Read the parameters; set each (verified by reading back), save, and print them."""
    changes = [parse_assignment(text) for text in assignments]  # all checked first
    with ExitStack() as stack:
        host = _open_host(stack, url, record)
        values = host.read_params()
        for index, value in changes:
            values = host.set_param(index, value)
            print(f"set {params.PARAMS[index].name} = {value} (verified)", file=sys.stderr)
        if save:
            host.save()
            values = host.read_params()
            print("saved to the board's flash", file=sys.stderr)
    if as_json:
        out.write(
            json.dumps({p.name: v for p, v in zip(params.PARAMS, values, strict=True)}) + "\n"
        )
    else:
        out.write(params_table(values) + "\n")
    return 0


def run_monitor(
    url: str,
    *,
    as_json: bool,
    duration: float | None,
    count: int | None,
    record: str | None,
    out: TextIO,
) -> int:
    """Print records as they arrive, until interrupted, `duration` or `count` records."""
    seen = 0
    with ExitStack() as stack:
        host = _open_host(stack, url, record)
        print(f"monitoring {url} (Ctrl-C to stop)", file=sys.stderr, flush=True)
        try:
            for event in host.events(duration):
                _show(host, event, out, as_json)
                seen += not isinstance(event, LinkStatus)
                if count is not None and seen >= count:
                    break
        finally:
            stats = host.state.stats
            print(
                f"monitor: {stats.records} records, {stats.errors} errors, "
                f"{stats.bytes_in} bytes in {host.now():.1f} s",
                file=sys.stderr,
            )
    return 0
