"""Issue 23.5: every `$ …` example of the README and of the documentation site runs, in
order, and prints what the document shows (issue 52: wherever an example moves).

Each document runs in a folder of its own. Boards a document starts (`$ appmode board
…`) are started, and the pty names it shows stand for theirs; so are the shares,
routers and ROS nodes it starts, shown by their first line. An example's output
matches when its lines come in order (`…` alone on a line stands for any lines, `…` in a
line for any text there). On a line of readings from a board in real time (a timed
`0.123 <` line, the console's velocity row) a number may differ from the document's by
20 % (at least 3, or 0.1 with decimals): a speed read at a slightly other moment;
elsewhere a duration may differ by 0.1 s or 20 %, and every other number is exact.
"""

from __future__ import annotations

import functools
import os
import re
import select
import selectors
import shlex
import subprocess
import sys
import time
from dataclasses import dataclass
from pathlib import Path

import pytest

from tests.support.processes import ROOT

DOCUMENTS = [ROOT / "README.md", *sorted(ROOT.joinpath("docs").rglob("*.md"))]

NOT_RUN = {
    "appmode ports": "lists this machine's serial ports, which differ from machine to machine",
    "cd examples/pytest_host && pytest -n 2": "tests/testing/test_plugin.py runs that project",
    "appmode conform bad.transcript": "an illustration of a failure: bad.transcript is an "
    "edited copy of a suite transcript, not shipped",
    "appmode conform --board /dev/pts/0 --board2 /dev/pts/1 --profile minibalance --yes": "the "
    "whole suite in real time (40 s) against a served board, whose ±0.3 s a machine loaded "
    "by two test runs overruns; tests/transcript/test_conformance.py runs three of "
    "its transcripts so, and the example before this one runs all on virtual time",
    "appmode web": "a server until Ctrl-C: tests/web drives it, and its page in Chromium",
    "appmode drive /dev/pts/1 --uart2": "a full-screen console: tests/console drives it in tmux",
    "appmode drive /dev/pts/0 /dev/pts/1": "a full-screen console: tests/console drives it in tmux",
    "appmode scan": "lists the Bluetooth modules near this machine: tests/bluetooth runs it "
    "against the BlueZ stand-in",
    "appmode board --bluetooth": "the BlueZ stand-in: tests/bluetooth starts it, and runs the "
    "commands of its page against it",
    "export DBUS_SYSTEM_BUS_ADDRESS='unix:path=/tmp/appmode-bus-3apg0o8e/bus,"
    "guid=91d20ecb8e5542c34ca59b3f6b087e63'": "the bus of the stand-in above",
    "appmode params ble://HC-08": "needs the stand-in above: tests/bluetooth runs it",
    "printf 'drive A\\nwait 1\\n' | appmode drive bt://02:CA:40:00:00:05": "needs the "
    "stand-in above: tests/bluetooth runs it",
    "appmode board --advertise": "registers with this machine's BlueZ, which has no adapter "
    "here: tests/bluetooth/test_advertise.py runs it against the stand-in",
    "appmode tap advertise:HC-08 ble://AA:BB:CC:DD:EE:FF --record phone.transcript": "a phone "
    "and a real car: tests/bluetooth/test_advertise.py taps a bleak program and a second "
    "simulated car",
}
"""Examples not run here, and why."""

SERVERS = ("appmode share", "appmode router", "appmode ros")
"""Servers a document starts, shown by their first line (the URL a share prints)."""
SWITCH = 2.0
"""Seconds between starting a board and the next command: the documents' board logs show
a person switching to another shell."""
NUMBER = re.compile(r"(-?\d+(?:\.\d+)?)")
LIVE = re.compile(r"\s*(\d+\.\d{3} |velocity |attitude |link up |APP port: )")
PTY = re.compile(r"/dev/pts/\d+")


@dataclass
class Example:
    line: int
    command: str
    expected: list[str]


def examples(document: Path) -> list[Example]:
    """A document's `$ …` commands, each with the lines shown after it in its block."""
    found: list[Example] = []
    block = False
    current: Example | None = None
    for number, line in enumerate(document.read_text(encoding="utf-8").splitlines(), 1):
        if line.startswith("```"):
            block, current = not block, None
        elif block and line.startswith("$ "):
            current = Example(number, line[2:], [])
            found.append(current)
        elif current is not None:
            current.expected.append(line)
    return found


def _tokens(line: str) -> list[str]:
    """Numbers, `…` and the words between them, whitespace runs as one space."""
    parts = re.split(r"(-?\d+(?:\.\d+)?|…)", " ".join(line.split()))
    return [part for part in parts if part]


def _same_number(expected: str, actual: str, live: bool) -> bool:
    if not NUMBER.fullmatch(actual):
        return False
    if not live and "." not in expected:
        return expected == actual
    e, a = float(expected), float(actual)
    slack = max(0.1 if "." in expected else 3.0, 0.2 * abs(e))
    return abs(e - a) <= slack


def is_live(line: str) -> bool:
    """A line of readings taken in real time: a timed line, the console's readings."""
    return LIVE.match(line) is not None


def line_matches(expected: str, actual: str, timed: bool) -> bool:
    """`…` in a line stands for any text; numbers as the module says."""
    want, got = _tokens(expected), "".join(_tokens(actual))
    live = timed and is_live(expected)

    @functools.cache
    def match(i: int, at: int) -> bool:
        if i == len(want):
            return at == len(got)
        token = want[i]
        if token == "…":
            return any(match(i + 1, k) for k in range(at, len(got) + 1))
        if NUMBER.fullmatch(token):
            number = NUMBER.match(got, at)
            return (
                number is not None
                and _same_number(token, number.group(0), live)
                and match(i + 1, number.end())
            )
        return got.startswith(token, at) and match(i + 1, at + len(token))

    return match(0, 0)


def output_matches(expected: list[str], actual: list[str], timed: bool) -> int | None:
    """None when `actual` matches; else the index of the first expected line that no
    way of matching got past."""
    reached = 0

    @functools.cache
    def match(i: int, j: int) -> bool:
        nonlocal reached
        reached = max(reached, i)
        if i == len(expected):
            return j == len(actual)
        if expected[i].strip() == "…":
            return any(match(i + 1, k) for k in range(j, len(actual) + 1))
        return (
            j < len(actual) and line_matches(expected[i], actual[j], timed) and match(i + 1, j + 1)
        )

    return None if match(0, 0) else reached


class Boards:
    """The boards a document starts, and the names it shows for their ptys."""

    def __init__(self, cwd: Path) -> None:
        self.cwd = cwd
        self.procs: list[subprocess.Popen[str]] = []
        self.names: dict[str, str] = {}  # the document's name → this run's pty

    def start(self, example: Example) -> list[str]:
        """A board the document starts: what it prints as it starts, stdout and stderr as
        a terminal shows them (issue 69.5: the document shows every one of those lines)."""
        proc = subprocess.Popen(
            [sys.executable, "-m", *shlex.split(example.command)],
            stdout=subprocess.PIPE,
            stderr=subprocess.STDOUT,
            cwd=self.cwd,
        )
        self.procs.append(proc)
        assert proc.stdout is not None
        shown = _start_up(proc.stdout.fileno())
        assert len(shown) >= 2, f"the board printed {shown}"
        for want, got in zip(example.expected, shown, strict=False):  # port, uart2, chassis
            named = PTY.search(want), PTY.search(got)
            if named[0] is not None and named[1] is not None:
                self.names[named[0].group(0)] = named[1].group(0)
        time.sleep(SWITCH)
        return shown

    def serve(self, example: Example) -> list[str]:
        """A server a document starts (`appmode share`, `appmode router`): its first line,
        as the document shows it."""
        said = self.cwd / f"server-{len(self.procs)}.err"
        with said.open("w") as errors:  # what it said, should it print nothing
            proc = subprocess.Popen(
                [sys.executable, "-m", *shlex.split(example.command)],
                stdout=subprocess.PIPE,
                stderr=errors,
                text=True,
                cwd=self.cwd,
                env=dict(os.environ, XDG_DATA_HOME=str(self.cwd / "data")),  # its host key
            )
        self.procs.append(proc)
        shown = [_line(proc.stdout)]
        if not shown[0]:  # it ended: its stderr says why
            proc.wait(10)
            shown += said.read_text().splitlines()
        time.sleep(SWITCH)
        return shown

    def to_run(self, command: str) -> str:
        return PTY.sub(lambda m: self.names.get(m.group(0), m.group(0)), command)

    def as_shown(self, text: str) -> str:
        mine = {actual: shown for shown, actual in self.names.items()}
        return PTY.sub(lambda m: mine.get(m.group(0), m.group(0)), text)

    def stop(self) -> None:
        for proc in self.procs:
            proc.terminate()
            proc.communicate(timeout=10)


QUIET = 1.0
"""Seconds a starting board is silent before what it printed counts as its start-up."""


def _start_up(fd: int) -> list[str]:
    """What a board prints as it starts: its lines until it is QUIET (20 s at most)."""
    data, deadline = b"", time.monotonic() + 20
    while (left := deadline - time.monotonic()) > 0:
        ready, _, _ = select.select([fd], [], [], QUIET if data else left)
        if not ready:
            break
        chunk = os.read(fd, 65536)
        if not chunk:
            break
        data += chunk
    return data.decode(errors="replace").splitlines()


def _line(stream: object) -> str:
    sel = selectors.DefaultSelector()
    sel.register(stream, selectors.EVENT_READ)  # type: ignore[arg-type]
    assert sel.select(20), "the board printed nothing in 20 s"
    return stream.readline().rstrip("\n")  # type: ignore[attr-defined,no-any-return]


def run_shell(command: str, cwd: Path) -> str:
    env = dict(os.environ, PYTHONUNBUFFERED="1", COLUMNS="80", XDG_DATA_HOME=str(cwd / "data"))
    prelude = f'appmode() {{ {shlex.quote(sys.executable)} -m appmode "$@"; }}\n'
    prelude += f'python() {{ {shlex.quote(sys.executable)} "$@"; }}\n'
    done = subprocess.run(
        ["bash", "-c", prelude + command],
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
        cwd=cwd,
        env=env,
        timeout=120,
        check=False,
    )
    return done.stdout


WITH_EXAMPLES = [
    document
    for document in DOCUMENTS
    if any(example.command not in NOT_RUN for example in examples(document))
]
"""The documents with examples to run."""


@pytest.mark.slow
@pytest.mark.parametrize("document", WITH_EXAMPLES, ids=lambda d: str(d.relative_to(ROOT)))
def test_every_example_runs_and_prints_what_its_document_shows(
    document: Path, tmp_path: Path
) -> None:
    (tmp_path / "examples").symlink_to(ROOT / "examples")
    boards = Boards(tmp_path)
    failures: list[str] = []
    name = document.relative_to(ROOT)
    try:
        for example in examples(document):
            if example.command in NOT_RUN:
                continue
            if example.command.startswith("appmode board"):
                out = "\n".join(boards.start(example))
                expected = example.expected[: len(out.splitlines())]  # its start-up lines
            elif example.command.startswith(SERVERS):
                out = "\n".join(boards.serve(example))
                expected = example.expected[:1]
            else:
                out = run_shell(boards.to_run(example.command), tmp_path)
                expected = example.expected
            shown = boards.as_shown(out).splitlines()
            timed = "| appmode decode" not in example.command  # decoding takes no time
            failed = output_matches(expected, shown, timed)
            if failed is not None:
                where = expected[failed] if failed < len(expected) else "(the end)"
                failures.append(
                    f"{name}:{example.line}: $ {example.command}\n  no match for: {where}\n"
                    + "\n".join(f"  | {line}" for line in shown)
                )
    finally:
        boards.stop()
    assert not failures, "\n\n".join(failures)


def test_the_examples_not_run_are_in_the_documents() -> None:
    listed = {e.command for document in DOCUMENTS for e in examples(document)}
    assert set(NOT_RUN) <= listed, "NOT_RUN names an example no document has"
    assert ROOT / "README.md" in WITH_EXAMPLES


def test_the_matcher_tells_a_right_output_from_a_wrong_one() -> None:
    shown = ["  0.048 < {A0:130:0:0}$    velocity x=0 y=130 z=0", "…", "  0.301 > Z   stop"]
    got = ["  0.052 < {A0:128:0:0}$ velocity x=0 y=128 z=0", "x", "y", "  0.300 > Z stop"]
    assert output_matches(shown, got, timed=True) is None
    assert output_matches(shown, got, timed=False) == 0  # exact numbers
    assert output_matches(shown, [*got[:3], "  0.300 > A stop"], timed=True) == 2
    assert output_matches(shown, [*got, "more"], timed=True) == 3  # the end is the end
    assert line_matches(" 0  max_speed  800  0–65535  500", " 0 max_speed 800 0–65535 500", False)
    assert not line_matches(" 0  max_speed  800", " 0  max_speed  500", True)
    assert line_matches(
        "the shipped suite: /…/appmode/suite", "the shipped suite: /a/b/appmode/suite", False
    )
    assert not line_matches(
        "the shipped suite: /…/appmode/suite", "the suite: /a/appmode/suite", False
    )
    assert line_matches(
        "  2.650 < {C800:10000:20:0:10:10:10:0:1}$    params max_speed=800 …",
        "  2.650 < {C800:10000:20:0:10:10:10:0:1}$ params max_speed=800 max_position=10000",
        True,
    )
