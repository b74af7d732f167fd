"""`appmode conform`: run transcripts against a board, on virtual or real time."""

from __future__ import annotations

import contextlib
import sys
import time
import xml.etree.ElementTree as ET
from collections.abc import Callable
from dataclasses import dataclass
from io import BytesIO
from pathlib import Path
from typing import TextIO

import serial

from appmode.board.firmware import Board
from appmode.board.profiles import Profile, profile_named
from appmode.board.store import MemoryStore
from appmode.errors import AppmodeError
from appmode.files import check_writable, write_whole
from appmode.host.app.client import Host
from appmode.host.link import LinkLost, Refused
from appmode.line.wire import CHASSIS, UART2_BAUD, Wire
from appmode.line.wire import UART2 as UART2_PORT
from appmode.ports.target import Target, both_ports
from appmode.ports.urls import open_link
from appmode.protocol import app, app_decoders, chassis, param_values, params
from appmode.protocol.formats import WRITERS
from appmode.protocol.reader import RECEIVED2, SENT, SENT2, PortsReader
from appmode.protocol.transcript import Transcript
from appmode.text import escaped, wrapped
from appmode.transcript.chassis_runs import feed_virtual, run_live_chassis
from appmode.transcript.matcher import Check
from appmode.transcript.reading import read_transcript

Progress = Callable[[str], None]


@dataclass(frozen=True, slots=True)
class Result:
    path: str
    title: str
    passed: bool
    seconds: float
    """Transcript time covered (virtual or real)."""
    wall: float
    failure: str | None = None
    skipped: str | None = None
    """Why the transcript was not run against this board."""


def run_virtual(transcript: Transcript) -> Result:
    """Run against a fresh embedded board on virtual time: no sleeping."""
    started = time.perf_counter()
    check = Check(transcript)
    needs = check.needs
    wire = Wire(Board(MemoryStore(), drive=needs.drive, profile=needs.profile), 9600)
    layout = needs.profile.a_layout
    decoder = layout.board_decoder()
    reader = PortsReader(drive=needs.drive, layout=layout)
    statuses = chassis.StatusDecoder()
    now = 0.0
    while not check.done and now <= check.end:
        # what arrived by `now` first: it came before what is sent at `now`
        _feed(check, decoder, wire.pump_timed(now))
        for when, data in wire.pump_timed(now, UART2_PORT):
            _feed2(check, reader, RECEIVED2, data, when)
        feed_virtual(check, statuses, wire, now)
        for port, data in check.due(now):
            wire.write(data, now, port)
            if port != CHASSIS:
                _feed2(check, reader, SENT2 if port == UART2_PORT else SENT, data, now)
        check.on_time(now)
        due = check.next_time()
        if due is None:
            break
        now = min(due, wire.board.next_slot())  # both lie after `now`
    return _result(transcript, check, now, time.perf_counter() - started)


def _feed2(check: Check, reader: PortsReader, direction: str, data: bytes, now: float) -> None:
    """Follow UART2: what it delivers (and what its decoder held when a frame sent changed
    the board's mode) goes to the check."""
    for shown, event in reader.feed(direction, data):
        if shown == RECEIVED2:
            check.on_record(event, now, UART2_PORT)


def _feed(
    check: Check, decoder: app_decoders.BoardDecoder, timed: list[tuple[float, bytes]]
) -> None:
    """Decode delivered bytes; each record counts at the time its last byte arrived."""
    if not timed:
        return
    times = [t for t, chunk in timed for _ in chunk]
    end = -decoder.buffered  # stream offset, relative to the new bytes, of the next event
    for event in decoder.feed(b"".join(chunk for _, chunk in timed)):
        end += len(event.raw)
        if isinstance(event, app.RECORDS):
            check.on_record(event, times[max(0, end - 1)])


def _result(transcript: Transcript, check: Check, now: float, wall: float) -> Result:
    if check.failure is None and not check.done:
        check.on_time(float("inf"))
    failure = check.failure
    return Result(transcript.path, transcript.title, failure is None, now, wall, failure)


def run_live(
    transcript: Transcript,
    url: Target,
    progress: Progress | None = None,
    url2: Target | None = None,
) -> Result:
    """Run in real time against any board URL (and its control port at `url2`)."""
    started = time.perf_counter()
    check = Check(transcript)
    link2 = None
    if check.uses_uart2:
        if url2 is None and url.simulated:
            url, url2 = both_ports(url)
        if url2 is None:
            why = "has UART2 lines: give the board's control port with --board2 URL"
            return Result(transcript.path, transcript.title, True, 0.0, 0.0, None, why)
    with Host(url, profile=check.needs.profile) as host, contextlib.ExitStack() as stack:
        if url2 is not None and check.uses_uart2:
            link2 = open_link(url2, timeout=0, baud=UART2_BAUD)
            stack.callback(link2.close)
        reader = PortsReader(drive=check.needs.drive, layout=check.needs.profile.a_layout)
        if check.needs.drive is not None:
            values = host.read_params()
            have = params.drive_type(values[params.SYSTEM_MODE])
            if have is not check.needs.drive:
                name = have.cli_name if have is not None else "invalid"
                message = (
                    f"{transcript.path}: needs a {check.needs.drive.cli_name} drive; the board "
                    f"at {url} reports {name} (system_mode {values[params.SYSTEM_MODE]}): set it "
                    f"with appmode params {url} --set system_mode=…, or skip this transcript"
                )
                return Result(
                    transcript.path,
                    transcript.title,
                    False,
                    0.0,
                    time.perf_counter() - started,
                    message,
                )
        # a transcript from the power-up keeps the board's time (a sim:// board's clock is
        # the host's, from its boot): counted from after the reads above, a host slow to
        # open the port (a loaded machine) saw the board's records early
        origin = 0.0 if check.needs.power_up and url.simulated else host.now()
        shown = -1
        while not check.done:
            now = host.now() - origin
            try:
                for port, data in check.due(now):
                    if port == UART2_PORT and link2 is not None:
                        link2.write(data)
                    else:
                        host.send(data)
                    _feed2(check, reader, SENT2 if port == UART2_PORT else SENT, data, now)
            except (LinkLost, Refused) as exc:
                check.failure = f"{transcript.path}: at {now:.3f} s: {exc}"
                break
            except (serial.SerialException, OSError) as exc:
                check.failure = f"{transcript.path}: at {now:.3f} s: UART2 link lost: {exc}"
                break
            due = check.next_time()
            most = 0.005 if link2 is not None else 0.05
            wait = most if due is None else max(0.0, min(most, due - now))
            for event in host.poll(wait):
                if isinstance(event, app.RECORDS):
                    check.on_record(event, host.now() - origin)
            if link2 is not None:
                try:
                    waiting = link2.in_waiting
                    data = link2.read(waiting) if waiting else b""
                except (serial.SerialException, OSError) as exc:
                    check.failure = f"{transcript.path}: UART2 link lost: {exc}"
                    break
                _feed2(check, reader, RECEIVED2, data, host.now() - origin)
            check.on_time(host.now() - origin)
            if progress is not None and int(now * 2) != shown:
                shown = int(now * 2)
                progress(f"{transcript.path}: {now:5.1f} / {check.end:.1f} s")
        now = host.now() - origin
    return _result(transcript, check, now, time.perf_counter() - started)


def _suite() -> Path:
    """The conformance suite: `appmode/suite` in an installed wheel (the build maps the
    repository's `transcripts/suite` there), else `transcripts/suite` of a checkout."""
    package = Path(__file__).parents[1]
    installed = package / "suite"
    return installed if installed.is_dir() else package.parent / "transcripts" / "suite"


SUITE = _suite()
"""The conformance suite shipped with appmode: `appmode conform` with no path runs it."""


def collect(paths: list[str]) -> list[Path]:
    """Transcript files from files and directories (searched recursively, sorted: their
    transcripts and MCAP recordings)."""
    found: list[Path] = []
    for name in paths:
        path = Path(name)
        if path.is_dir():
            found += sorted(p for p in path.rglob("*") if p.suffix.lower() in WRITERS)
        elif path.exists():
            found.append(path)
        else:
            raise AppmodeError(f"no such transcript or directory: {name}")
    if not found:
        raise AppmodeError(f"no {' or '.join(WRITERS)} files in {', '.join(paths)}")
    return found


def write_junit(path: str, results: list[Result]) -> None:
    """A JUnit XML report, written whole or not at all."""
    suite = ET.Element(
        "testsuite",
        name="appmode conform",
        tests=str(len(results)),
        failures=str(sum(not r.passed for r in results)),
        skipped=str(sum(r.skipped is not None for r in results)),
        time=f"{sum(r.wall for r in results):.3f}",
    )
    for result in results:
        case = ET.SubElement(
            suite,
            "testcase",
            classname="appmode.conform",
            name=result.path,
            time=f"{result.wall:.3f}",
        )
        if result.failure is not None:
            failure = ET.SubElement(case, "failure", message=result.failure.splitlines()[0])
            failure.text = result.failure
        elif result.skipped is not None:
            ET.SubElement(case, "skipped", message=result.skipped)
    data = BytesIO()
    ET.ElementTree(suite).write(data, encoding="utf-8", xml_declaration=True)
    write_whole(path, data.getvalue(), "JUnit report")


def run_conform(
    paths: list[str],
    board: Target | None,
    junit: str | None,
    out: TextIO,
    profile: str = "sheet",
    board2: Target | None = None,
    chassis: bool = False,
) -> int:
    """Run every transcript for `profile` (on a `chassis` port: none to put back); one line
    each; exit status 1 on any failure."""
    if junit:
        check_writable(junit, "JUnit report")
    if paths:
        transcripts = [read_transcript(path) for path in collect(paths)]
    else:
        out.write(f"the shipped suite: {SUITE}\n")
        transcripts = [
            read_transcript(path, name=str(path.relative_to(SUITE.parent)))
            for path in collect([str(SUITE)])
        ]  # all readable before any runs
    for transcript in transcripts:
        for warning in transcript.warnings:
            print(f"appmode: WARNING: {warning}", file=sys.stderr)
        if not transcript.entries:
            raise AppmodeError(f"{transcript.path} has no '>' or '<' lines: nothing to check")
    chosen = profile_named(profile)
    transcripts = _for_profile(transcripts, chosen, out)
    interactive = sys.stderr.isatty()

    def progress(text: str) -> None:
        if interactive:
            print(f"\r\033[K{text}", end="", file=sys.stderr, flush=True)

    live = board is not None and not board.simulated and not chassis  # sim://: a new board
    found = _read_params(board, chosen) if live and board is not None else None
    results: list[Result] = []
    between = None
    if board is not None and found is not None:
        url, values = board, found
        between = lambda: put_back(url, values, chosen)  # noqa: E731 - the run's own undo
    try:
        _run_all(transcripts, board, progress, interactive, results, out, board2, between)
    finally:
        if board is not None and found is not None:
            started = transcripts[: len(results) + 1]  # the one cut short too
            saved = any(_saves(t) for t in started)
            out.write(restore_params(board, found, chosen, saved) + "\n")
    if board2 is not None and not board2.simulated and _sent_on_uart2(transcripts, results):
        out.write(wrapped(f"note: {TAKEN_OVER}") + "\n")
    failed = sum(not r.passed for r in results)
    skipped = sum(r.skipped is not None for r in results)
    target = f"the embedded simulated board ({profile} profile)" if board is None else board
    counts = f"{len(results) - failed - skipped} passed, {failed} failed"
    counts += f", {skipped} skipped" if skipped else ""
    out.write(f"{counts} against {target}\n")
    if junit:
        write_junit(junit, results)
    return 1 if failed else 0


TAKEN_OVER = (
    "the board's control port (UART2) has taken over its motion (see appmode protocol 8.3): "
    "drive letters on the APP port (the phone app, appmode send, drive) do nothing until "
    "the board is reset or powered off; nothing sent can give the APP port its motion back"
)


def _saves(transcript: Transcript) -> bool:
    """Whether `transcript` sends a save ({Q:W}): the flash may hold what the run set."""
    decoder = app_decoders.HostDecoder()
    return any(
        isinstance(event, app.SaveParams)
        for entry in transcript.entries
        if entry.direction == SENT
        for event in decoder.feed(entry.data)
    )


def _sent_on_uart2(transcripts: list[Transcript], results: list[Result]) -> bool:
    """Whether a transcript that ran on the board sent on its control port."""
    return any(
        result.skipped is None and any(e.direction == SENT2 for e in transcript.entries)
        for transcript, result in zip(transcripts, results, strict=False)
    )


def _run_all(
    transcripts: list[Transcript],
    board: Target | None,
    progress: Progress,
    interactive: bool,
    results: list[Result],
    out: TextIO,
    board2: Target | None = None,
    between: Callable[[], str | None] | None = None,
) -> None:
    """Run each transcript and write its line; `between` (a real board) puts back what a
    transcript changed before the next runs, so that none relies on the ones before."""
    for transcript in transcripts:
        needs = Check(transcript).needs
        if board is None:
            result = run_virtual(transcript)
        elif needs.power_up and not board.simulated:
            why = "starts at the board's power-up: run it on virtual time (no --board)"
            result = Result(transcript.path, transcript.title, True, 0.0, 0.0, None, why)
        elif Check(transcript).uses(CHASSIS):
            started = time.perf_counter()
            check, reached = run_live_chassis(transcript, board, progress)
            result = _result(transcript, check, reached, time.perf_counter() - started)
        else:
            result = run_live(transcript, board, progress, board2)
            if interactive:
                print("\r\033[K", end="", file=sys.stderr, flush=True)
        results.append(result)
        verdict = "SKIP" if result.skipped else "PASS" if result.passed else "FAIL"
        if board is None:
            timing = f"{result.seconds:.2f} s of virtual time in {result.wall:.3f} s"
        else:
            timing = f"{result.wall:.2f} s"
        path = escaped(str(result.path))  # a suite's file names come from outside
        if result.skipped is not None:
            out.write(f"{verdict}  {path}  ({escaped(result.skipped)})\n")
        else:
            out.write(f"{verdict}  {path}  ({timing})\n")
        if result.failure is not None:
            out.write(f"      {escaped(result.failure)}\n")
        failed = between() if between is not None and not result.skipped else None
        if failed is not None:
            out.write(f"      {failed}\n")
        out.flush()


def _for_profile(transcripts: list[Transcript], profile: Profile, out: TextIO) -> list[Transcript]:
    """The transcripts written for `profile` (`@board profile=…`, default sheet); says how
    many others there were."""
    chosen = [t for t in transcripts if Check(t).needs.profile is profile]
    others = len(transcripts) - len(chosen)
    if others:
        out.write(
            f"{len(chosen)} transcript(s) for the {profile.name} profile; {others} for other "
            "profiles not run (--profile NAME runs those)\n"
        )
    if not chosen:
        raise AppmodeError(f"none of these transcripts is for the {profile.name} profile")
    return chosen


def _read_params(url: Target, profile: Profile) -> tuple[int, ...]:
    with Host(url, profile=profile) as host:
        try:
            return host.read_params()
        except AppmodeError as exc:
            raise AppmodeError(f"before running: {exc}") from None


def _set_back(host: Host, values: tuple[int, ...]) -> list[int]:
    """Set the parameters that differ from `values` back (verified); which did."""
    now = host.read_params()
    changed = [i for i, (a, b) in enumerate(zip(now, values, strict=True)) if a != b]
    for index in changed:
        host.set_param(index, values[index])
    return changed


def put_back(url: Target, values: tuple[int, ...], profile: Profile) -> str | None:
    """Between two transcripts on a real board: its parameters back to `values`
    (verified, not saved); what went wrong, in a line, or None."""
    try:
        with Host(url, profile=profile) as host:
            _set_back(host, values)
    except AppmodeError as exc:
        return f"could not put the parameters back before the next transcript: {exc}"
    return None


def restore_params(
    url: Target, values: tuple[int, ...], profile: Profile, saved: bool = False
) -> str:
    """Set the board's parameters back to `values` (verified), and send `{Q:W}` only when
    a transcript `saved` (the flash may hold what it set): what a run against a real board
    changed is undone, with no flash write for nothing. Returns what was done, a line."""
    try:
        with Host(url, profile=profile) as host:
            changed = _set_back(host, values)
            if saved:
                host.save()
    except AppmodeError as exc:
        pairs = zip(profile.a_layout.params, values, strict=True)
        shown = ", ".join(f"{p.name}={param_values.to_user(p, v)}" for p, v in pairs)
        return f"could not restore the parameters found at the start ({shown}): {exc}"
    if saved:
        return (
            f"restored the parameters found at the start ({len(changed)} had changed) and "
            "sent {Q:W} to save them (a transcript had saved)"
        )
    if changed:
        return (
            f"restored the parameters found at the start ({len(changed)} had changed; not "
            "saved: no transcript saved, so the flash holds what it held)"
        )
    return "the parameters are as found at the start: nothing to restore, nothing saved"
