"""Fault injection: the host under a faulty link, and the board under corrupted frames."""

from __future__ import annotations

import random
from typing import Any

import pytest

from appmode.board.firmware import Board
from appmode.errors import AppmodeError
from appmode.host.app.client import Host
from appmode.host.app.state import HostState
from appmode.line.faults import Faults, FaultSpec, FaultyPort
from appmode.ports.sim import SimSerial
from appmode.ports.urls import open_link
from appmode.protocol import params
from tests.support.processes import board_process, run

HEAVY = "drop:0.005,corrupt:0.01,dup:0.005,chatter:0.002,split:0.5,delay:0.01"
MODERATE = "drop:0.002,corrupt:0.002,dup:0.002,chatter:0.001,split:0.5,delay:0.01"


def board_of(host: Host) -> Board:
    link = host.link
    assert isinstance(link, SimSerial) and link.board is not None
    return link.board


def test_spec_parsing() -> None:
    spec = FaultSpec.parse("drop:0.1,seed:4,delay:0.02")
    assert (spec.drop, spec.seed, spec.delay, spec.active) == (0.1, 4, 0.02, True)
    assert not FaultSpec.parse("").active
    for bad, message in (
        ("drop", "use name:value"),
        ("drop:x", "not a number"),
        ("drop:2", "between 0 and 1"),
        ("wobble:1", "use name:value"),
    ):
        with pytest.raises(ValueError, match=message):
            FaultSpec.parse(bad)


def test_faults_are_seeded_and_counted() -> None:
    spec = FaultSpec(drop=0.1, dup=0.1, corrupt=0.1, chatter=0.01)
    data = bytes(range(256)) * 20
    one, two = Faults(spec, random.Random(5)), Faults(spec, random.Random(5))
    assert one.apply(data) == two.apply(data)
    counts = one.counts
    assert counts.dropped > 300 and counts.duplicated > 300 and counts.corrupted > 300
    assert counts.chatter > 10


@pytest.mark.parametrize("seed", range(8))
def test_host_never_reports_a_parameter_it_did_not_read_intact(seed: int) -> None:
    """Heavy faults: a read may fail (clearly), but what it reports is always true."""
    with Host(f"sim://?faults={HEAVY},seed:{seed}") as host:
        try:
            values = host.read_params()
        except AppmodeError as exc:
            assert "no parameters from" in str(exc) and "the link is noisy" in str(exc)
        else:
            assert values == params.DEFAULTS
        try:
            values = host.set_param(5, 4242)
        except AppmodeError as exc:
            assert "velocity_kp" in str(exc) or "no parameters" in str(exc)
        else:
            assert values[5] == 4242 == board_of(host).params[5]
        list(host.events(1.0))
        stats = host.state.stats
        assert stats.errors > 0 and stats.discarded > 0, "what was discarded is counted"
        assert stats.recent_errors(host.now()) > 0, "the link shows as degraded"


@pytest.mark.parametrize("seed", range(4))
def test_moderate_faults_reads_and_writes_succeed(seed: int) -> None:
    with Host(f"sim://?faults={MODERATE},seed:{seed}") as host:
        assert host.read_params() == params.DEFAULTS
        for index, value in ((0, 800), (7, 123456), (8, 0x13)):
            assert host.set_param(index, value)[index] == value
            assert board_of(host).params[index] == value


class DigitFlip:
    """A link that turns the first `{0:800}` into `{0:900}`: undetectable on the wire."""

    def __init__(self, port: Any) -> None:
        self.port = port
        self.flipped = False

    def __getattr__(self, name: str) -> Any:
        return getattr(self.port, name)

    def write(self, data: bytes) -> int:
        if not self.flipped and b"{0:800}" in data:
            self.flipped = True
            data = data.replace(b"{0:800}", b"{0:900}")
        return int(self.port.write(data))


def test_a_write_corrupted_into_another_valid_frame_is_caught_and_retried() -> None:
    links: list[DigitFlip] = []

    def opener(url: object) -> Any:
        links.append(DigitFlip(open_link(url)))
        return links[-1]

    with Host("sim://?pace=0", opener=opener) as host:
        assert host.set_param(0, 800)[0] == 800
        sim = links[0].port
        assert links[0].flipped and isinstance(sim, SimSerial) and sim.board is not None
        assert sim.board.params[0] == 800


def test_board_applies_only_frames_valid_as_received() -> None:
    """Every single-byte corruption of `{0:800}`. With no checksum, a corruption that
    makes another valid frame (a digit for a digit, or `}` cutting the value short)
    cannot be told from a real command by any board; all others change nothing. The
    host's verified write (read back, retry) is the defence, tested above."""
    frame = b"{0:800}"
    undetectable = set()
    for position in range(len(frame)):
        for value in range(256):
            corrupted = frame[:position] + bytes([value]) + frame[position + 1 :]
            board = Board()
            board.receive(corrupted, 0.0)
            if board.params != list(params.DEFAULTS):
                undetectable.add(corrupted)
    digit_for_digit = {
        frame[:p] + bytes([d]) + frame[p + 1 :] for p in (1, 3, 4, 5) for d in b"0123456789"
    }
    cut_short = {b"{0:8}0}", b"{0:80}}"}
    no_change = {b"{0:500}", b"{9:800}"}  # 500 is already the value; there is no parameter 9
    assert undetectable == (digit_for_digit | cut_short) - no_change


def test_faulty_port_wraps_any_link() -> None:
    with board_process("--listen", "0", "--quiet") as board:
        spec = FaultSpec.parse(f"{MODERATE},seed:1")
        with Host(board.url, opener=lambda url: FaultyPort(open_link(url), spec)) as host:
            assert host.read_params() == params.DEFAULTS
            assert host.set_param(0, 640)[0] == 640


def test_degraded_clears_after_a_quiet_window() -> None:
    state = HostState()
    state.feed(b"{A0:0:0:0}$xx{A1:2:3:0}$", 0.0)  # noise between records is an error
    assert state.stats.recent_errors(1.0) == 1
    assert state.stats.recent_errors(5.1) == 0


def test_monitor_and_console_survive_a_faulty_link() -> None:
    done = run("monitor", f"sim://?faults={HEAVY},seed:2", "--duration", "2")
    assert done.returncode == 0 and "Traceback" not in done.stderr
    assert "monitor:" in done.stderr and " 0 errors" not in done.stderr
    script = b"drive A\nwait 1\nstatus\nstop\n"
    done = run("drive", "--keep-going", f"sim://?faults={HEAVY},seed:3", stdin=script)
    assert "Traceback" not in done.stderr and "DEGRADED" in done.stdout
    # a read may fail on such a link: then it says so, and the script's status is 1
    failed = "appmode: error: no parameters" in done.stderr
    assert done.returncode == (1 if failed else 0), done.stderr
