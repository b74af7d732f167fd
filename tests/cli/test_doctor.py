"""Issue 23.1: `appmode doctor` finds the car, port by port, and says what to fix."""

from __future__ import annotations

import json
import os
import pty
import shutil
import subprocess
import sys
import threading
import time
import tty
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

import pytest
import serial

from appmode.board.profiles import MINIBALANCE, SHEET
from appmode.cli import main as cli_main
from appmode.cli.doctor import fix, verdict
from appmode.host import heard, probe
from appmode.ports.target import parse_target
from appmode.protocol import app, app_decoders, chassis, control_decoders, params
from tests.support.processes import ROOT, appmode_cmd, board_process, run


def doctor(*urls: str, wrap: list[str] | None = None) -> tuple[int, list[dict[str, Any]], str]:
    """`appmode doctor --json URLS`: its exit status, one finding per port, its stderr."""
    done = subprocess.run(
        [*(wrap or []), *appmode_cmd("doctor", "--json", *urls)],
        capture_output=True,
        text=True,
        timeout=60,
        cwd=ROOT,
        check=False,
    )
    found = [json.loads(line) for line in done.stdout.splitlines()]
    assert [f["port"] for f in found] == list(urls), done.stderr
    return done.returncode, found, done.stderr


def read_all(master: int) -> bytes:
    """All a pty's terminal side was sent, once that side is closed (a read returns what
    one pass of the line discipline holds, not all of it)."""
    chunks = []
    try:
        while chunk := os.read(master, 65536):
            chunks.append(chunk)
    except OSError:  # EIO: the terminal side is closed and all was read
        pass
    finally:
        os.close(master)
    return b"".join(chunks)


@contextmanager
def silent_pty() -> Iterator[str]:
    """A pseudo-terminal nobody writes to."""
    master, slave = pty.openpty()
    tty.setraw(slave)
    try:
        yield os.ttyname(slave)
    finally:
        os.close(master)
        os.close(slave)


@pytest.mark.timing
def test_a_minibalance_car_a_car_at_the_wrong_rate_and_a_silent_port_in_under_10_s() -> None:
    with (
        board_process("--pty", "--profile", "minibalance", "-q") as mini,
        board_process("--pty", "--baud", "38400", "-q") as fast,
        silent_pty() as quiet,
    ):
        start = time.monotonic()
        status, (car, other, nothing, uart2), _ = doctor(mini.url, fast.url, quiet, mini.uart2)
        took = time.monotonic() - start
    assert took < 10
    assert status == 0
    assert car["kind"] == "app" and car["baud"] == 9600 and car["profile"] == "minibalance"
    assert tuple(car["params"].values()) == MINIBALANCE.defaults
    assert car["fix"] == f"drive it with: appmode drive {mini.url} --profile minibalance"
    # the other car's module runs at 38400: garbled at 9600 and 115200, records at 38400
    assert other["kind"] == "app" and other["baud"] == 38400 and other["profile"] == "sheet"
    assert [h["baud"] for h in other["heard"]] == [9600, 115200, 38400]
    assert other["heard"][0]["bytes"] > 0 and other["heard"][0]["records"] == 0
    assert tuple(other["params"].values()) == SHEET.defaults
    assert other["fix"] == f"drive it with: appmode drive '{fast.url}?baud=38400'"
    assert "runs at 38400, not 9600" in other["verdict"]
    assert nothing["kind"] == "silent" and not nothing["car"]
    assert [h["baud"] for h in nothing["heard"]] == [9600, 115200]
    assert "check that the car is on" in nothing["fix"]
    # the reference firmware's UART2 carries its status bursts at 115200
    assert uart2["kind"] == "uart2" and uart2["baud"] == 115200
    assert "status bursts" in uart2["verdict"]


def test_it_sends_only_parameter_reads_and_nothing_to_a_silent_port(tmp_path: Any) -> None:
    record = tmp_path / "board.transcript"
    with board_process("--pty", "--record", str(record), "-q") as board:
        status, (found, quiet), _ = doctor(board.url, board.uart2)
    assert status == 0 and found["kind"] == "app" and quiet["kind"] == "silent"
    lines = record.read_text().splitlines()
    sent = [line.split(" ", 2)[2] for line in lines if " > " in line or " 2> " in line]
    assert sent and set(sent) == {"{Q:P}"}, sent  # no letter, nothing on UART2


@pytest.mark.slow
def test_text_is_not_a_board_and_params_says_so() -> None:
    master, slave = pty.openpty()
    tty.setraw(slave)
    path = os.ttyname(slave)
    talk = subprocess.Popen(
        [
            sys.executable,
            "-c",
            "import os,sys,time\nwhile True:\n"
            f" os.write({master}, b'Debian GNU/Linux 12 login: '); time.sleep(0.2)",
        ],
        pass_fds=(master,),
    )
    try:
        status, (found,), _ = doctor(path)
        done = run("params", path)
    finally:
        talk.kill()
        talk.wait()
        os.close(master)
        os.close(slave)
    assert status == 1 and found["kind"] == "text"
    assert "not a board: it sends text at 9600 bps ('Debian GNU/Linux" in found["verdict"]
    assert done.returncode == 2
    assert f"what answers at {path} is not a board:" in done.stderr
    assert "a pty path may have been reused" in done.stderr
    assert "appmode doctor" in done.stderr


def test_a_busy_port_names_the_process_that_holds_it() -> None:
    with board_process("--pty", "-q") as board, serial.Serial(board.url, exclusive=True):
        status, (found,), _ = doctor(board.url)
    assert status == 1 and found["kind"] == "unopened"
    assert found["verdict"] == f"cannot be opened: {board.url} is busy"
    assert f"(pid {os.getpid()}, holding its lock)" in found["fix"]


def test_a_port_without_permission_says_which_group_to_join() -> None:
    with silent_pty() as path:
        if os.geteuid() == 0:  # root opens anything: take away the capabilities that do it
            setpriv = shutil.which("setpriv")
            assert setpriv, "the test needs setpriv (util-linux) when run as root"
            os.chown(path, 65534, 65534)
            os.chmod(path, 0o600)
            wrap = [setpriv, "--bounding-set", "-dac_override,-dac_read_search,-fowner", "--"]
        else:
            os.chmod(path, 0)
            wrap = []
        status, (found,), _ = doctor(path, wrap=wrap)
    assert status == 1 and found["kind"] == "unopened"
    assert found["verdict"] == f"cannot be opened: permission denied opening {path}"
    assert found["fix"].startswith("add yourself to the ")
    assert "sudo usermod -aG" in found["fix"]


def test_a_missing_rfcomm_port_gets_the_bluetooth_steps() -> None:
    status, (found,), _ = doctor("/dev/rfcomm97")
    assert status == 1 and found["verdict"] == "cannot be opened: no such port /dev/rfcomm97"
    assert "rfcomm bind 0 MAC 1" in found["fix"] and "bluetoothctl" in found["fix"]
    assert "plugged in" not in found["fix"]


def test_the_embedded_boards_of_both_profiles() -> None:
    status, (sheet, mini), _ = doctor("sim://", "sim://?profile=minibalance")
    assert status == 0
    assert sheet["profile"] == "sheet" and sheet["fix"] == "drive it with: appmode drive sim://"
    assert tuple(sheet["params"].values()) == SHEET.defaults
    # it boots when opened: its start-up text, then records from 1.4 s
    assert mini["profile"] == "minibalance" and mini["baud"] == 9600, mini
    assert tuple(mini["params"].values()) == MINIBALANCE.defaults


def test_the_text_verdicts_fit_80_columns() -> None:
    with silent_pty() as quiet:
        done = run("doctor", "sim://", quiet, "/dev/rfcomm97")
    assert done.returncode == 0
    lines = done.stdout.splitlines()
    assert max(map(len, lines)) <= 80
    assert lines[0].startswith("ok sim://: this is a car: APP port, sheet firmware (a record")
    assert "-- /dev/rfcomm97: cannot be opened: no such port /dev/rfcomm97" in lines
    assert "   drive it with: appmode drive sim://" in lines


def test_progress_shows_on_a_terminal_and_is_cleared() -> None:
    master, slave = pty.openpty()
    with silent_pty() as quiet:
        done = subprocess.run(
            appmode_cmd("doctor", quiet),
            stdout=subprocess.PIPE,
            stderr=slave,
            cwd=ROOT,
            timeout=60,
            check=False,
        )
    os.close(slave)
    shown = read_all(master).decode()
    assert done.returncode == 1
    assert f"doctor: 0 of 1 port checked · {quiet}: listening at 9600 bps" in shown
    assert f"{quiet}: listening at 115200 bps" in shown
    assert shown.endswith("\r\x1b[K")


def test_no_ports_at_all_says_how_to_connect_one(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    monkeypatch.setattr("appmode.ports.listing.serial_ports", list)
    monkeypatch.setenv("DBUS_SYSTEM_BUS_ADDRESS", f"unix:path={tmp_path}/no-bus")
    assert cli_main.main(["doctor"]) == 1
    bluetooth, ports = capsys.readouterr().err.split("\n", 1)
    assert bluetooth.startswith("doctor: Bluetooth not looked for: no Bluetooth here")
    assert ports.startswith("no serial ports found: plug in the USB-UART adapter")
    assert cli_main.main(["doctor", "--no-bluetooth"]) == 1
    assert capsys.readouterr().err.startswith("no serial ports found")


def timed_records(period_ms: float, records: list[bytes]) -> heard.Heard:
    one = heard.Heard(9600)
    decoders = (
        app_decoders.BoardDecoder(b_fields=None),
        control_decoders.ReplyDecoder(wheels=None),
        chassis.StatusDecoder(),
    )
    for i, record in enumerate(records):
        one.feed(record, i * period_ms / 1000, *decoders)
    return one


def test_the_firmware_is_told_by_what_it_sends() -> None:
    """Issue 53.4: field counts, value patterns and the period, against the shipped
    profiles' files."""
    sheet_a, sheet_b = b"{A0:0:0:0}$", b"{B0:0:0:100}$"
    mini_a = b"{A0:0:100:0}$"  # |0.7x|, |0.7y|, battery: the B record's battery too
    balance_a, balance_b = b"{A0:0:95:2}$", b"{B2:0:0}$"  # B: angle, left, right
    assert heard.firmware(timed_records(50, [sheet_a, sheet_b] * 8).sent)[0] is SHEET
    assert heard.firmware(timed_records(60, [mini_a, sheet_b] * 8).sent)[0] is MINIBALANCE
    # the values decide even when a loaded host's period misleads (60 ms for the sheet)
    assert heard.firmware(timed_records(60, [sheet_a, sheet_b] * 8).sent)[0] is SHEET
    found, _ = heard.firmware(timed_records(50, [balance_a, balance_b] * 8).sent)
    assert found is not None and found.name == "balance"
    # B records of two fields: no shipped profile; the nearest says why
    found, nearest = heard.firmware(timed_records(50, [balance_a, b"{B0:0}$"] * 8).sent)
    assert found is None and nearest.profile.name == "balance"
    assert nearest.against == ("B records of 2 fields (3 here)",)
    # far off every period (400 ms) and records of no shipped shape
    found, _ = heard.firmware(timed_records(400, [b"{A-5:0:0:0}$", b"{B0:0}$"] * 8).sent)
    assert found is None
    # held up and delivered in a burst (a loaded host): the period says nothing, the
    # values still do (a battery of -740 %: the minibalance's before its motors are on)
    dead = [b"{A0:0:-740:0}$", b"{B0:0:0:-740}$"] * 8
    burst = timed_records(60, dead)
    burst.record_times[:8] = [burst.record_times[7]] * 8
    assert not burst.steady and timed_records(60, dead).steady
    assert heard.firmware(burst.sent)[0] is MINIBALANCE
    # the last record held up 0.7 s (the host not scheduled): 160 ms on average, far
    # from the minibalance's 60–90; the period says nothing then either
    held = timed_records(60, dead[:8])
    held.record_times[-1] += 0.7
    assert not held.steady and round(held.period_ms or 0) == 160
    assert heard.firmware(held.sent)[0] is MINIBALANCE
    # its motors come on while it is heard: the battery changes between an A and a B
    waking = dead[:5] + [mini_a, b"{B0:0:0:100}$"] * 6
    assert heard.firmware(timed_records(60, waking).sent)[0] is MINIBALANCE
    c = app.encode(app.ParamsRecord(params.DEFAULTS))
    # a long record keeps the reference loop waiting longer (§13): still that firmware
    mixed = timed_records(MINIBALANCE.record_period_ms(len(c)), [c] * 6)
    assert heard.firmware(mixed.sent)[0] is MINIBALANCE


def test_a_file_or_a_folder_is_not_a_serial_port(tmp_path: Any) -> None:
    plain = tmp_path / "notes.txt"
    plain.write_text("hello\n")
    status, (file, folder), _ = doctor(str(plain), str(tmp_path))
    assert status == 1
    assert (
        file["verdict"] == f"cannot be opened: {plain} is not a serial port (not a terminal device)"
    )
    assert folder["verdict"] == f"cannot be opened: {tmp_path} is not a serial port (a folder)"
    assert file["fix"] == "name the car's port; list ports with: appmode ports"
    assert plain.read_text() == "hello\n"  # opened, never written
    bad = run("doctor", "sim://?bogus=1")  # a URL is read once, with the command line
    assert bad.returncode == 2 and "unknown sim:// option 'bogus'" in bad.stderr
    assert len(bad.stderr.strip().splitlines()) == 1, bad.stderr


def test_a_port_that_goes_away_while_listened_to_is_said_so() -> None:
    master, slave = pty.openpty()
    path = os.ttyname(slave)
    closing = threading.Timer(0.3, os.close, (master,))
    closing.start()
    try:
        found = probe.probe(parse_target(path), threading.Event(), lambda text: None)
    finally:
        closing.join()
        os.close(slave)
    assert found.kind == "lost" and not found.is_car
    assert verdict(found).startswith("it opened, then failed while listening")
    assert "the device went away" in fix(found)


@contextmanager
def spewing_pty(code: str) -> Iterator[str]:
    """A pseudo-terminal that a process writes to (`code`, with `master` its end)."""
    master, slave = pty.openpty()
    tty.setraw(slave)
    spew = subprocess.Popen(
        [sys.executable, "-c", f"import os,sys,time\nmaster = {master}\n{code}"],
        pass_fds=(master,),
    )
    try:
        yield os.ttyname(slave)
    finally:
        spew.kill()
        spew.wait()
        os.close(master)
        os.close(slave)


def test_a_device_streaming_00_ff_is_not_a_car_s_control_port() -> None:
    """Issue 49.11: it was 'a car's control port … drive it with: appmode drive … --uart2'."""
    with spewing_pty("while True:\n os.write(master, b'\\x00\\xff' * 256); time.sleep(0.01)") as p:
        status, (found,), _ = doctor(p)
    assert status == 1, found
    assert found["kind"] != "uart2" and not found["car"], found
    assert "--uart2" not in found["fix"]


def test_text_is_told_as_quickly_as_silence() -> None:
    """Issue 49.11: a port sending plain text took 20 s (2.5 s at each of eight rates)."""
    code = "while True:\n os.write(master, b'Debian GNU/Linux 12 login: '); time.sleep(0.2)"
    with spewing_pty(code) as path:
        started = time.monotonic()
        status, (found,), _ = doctor(path)
        took = time.monotonic() - started
    assert status == 1 and found["kind"] == "text"
    assert len(found["heard"]) == 1, found["heard"]
    assert took < 8, took


def test_a_balance_car_is_named_and_a_car_of_no_shipped_profile_is_told_how_to_write_one(
    tmp_path: Path,
) -> None:
    """Issue 53.4, end to end: boards serving the balance profile and a user's own."""
    own = tmp_path / "twofield.toml"
    text = (ROOT / "appmode" / "protocol" / "profiles" / "balance.toml").read_text()
    own.write_text(
        text.replace('name = "balance"', 'name = "twofield"').replace(
            '  { name = "angle", label = "balance angle", unit = "°" },\n  { name = "encoder_left"',
            '  { name = "encoder_left"',
        )
    )
    with (
        board_process("--pty", "--profile", "balance", "-q") as balance,
        board_process("--pty", "--profile", str(own), "-q") as other,
    ):
        status, (car, unknown), _ = doctor(balance.url, unknown_url := other.url)
    assert status == 0
    assert car["profile"] == "balance", car
    assert car["params"]["balance_kp"] == 300 and car["params"]["velocity_ki"] == 0.4
    assert car["fix"] == f"drive it with: appmode drive {balance.url} --profile balance"
    assert unknown["kind"] == "app" and unknown["profile"] is None
    assert "unknown firmware" in unknown["verdict"]
    assert unknown["fix"].startswith(
        "its records fit no shipped profile (nearest: balance, but B records of 2 fields "
        "(3 here)): write one for it, starting from appmode profile show balance --toml"
    )
    assert unknown["fix"].endswith(f"appmode drive {unknown_url} --profile mycar.toml")


def test_bursts_heard_at_every_rate_are_the_control_port_s_at_its_own(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """A pty has no rate: a control port on one is read clean at 9600 too. Its bursts at
    115200 were fewer than ENOUGH in a loaded moment, and doctor said UART2 at 9600."""
    bursts = {probe.APP_BAUD: 16, probe.UART2_BAUD: 2, 38400: 0}

    def listen(
        url: object, baud: int, seconds: float, stop: threading.Event
    ) -> tuple[heard.Heard, serial.SerialBase]:
        count = bursts.get(baud, 0)
        one = heard.Heard(baud, seconds, 3 * count, uart2_bytes=3 * count, uart2_bursts=count)
        return one, serial.serial_for_url("loop://")

    monkeypatch.setattr(probe, "listen", listen)
    target = parse_target("/dev/ttyUSB7")
    finding = probe.probe(target, threading.Event(), lambda text: None)
    assert finding.kind == "uart2" and finding.baud == probe.UART2_BAUD, finding


def test_doctor_says_when_pypis_other_appmode_shares_the_environment(tmp_path: Path) -> None:
    """Issue 79.1: PyPI's `appmode` is a Jupyter extension that installs a package of the
    same import name; installed beside appmode-car, one overwrites the other's files."""
    quiet = run("doctor", "--no-bluetooth", "--json", str(tmp_path / "no-port"))
    assert "Jupyter" not in quiet.stderr, quiet.stderr
    info = tmp_path / "site" / "appmode-1.3.0.dist-info"
    info.mkdir(parents=True)
    (info / "METADATA").write_text("Metadata-Version: 2.1\nName: appmode\nVersion: 1.3.0\n")
    path = os.pathsep.join([str(ROOT), str(tmp_path / "site")])
    done = run("doctor", "--no-bluetooth", str(tmp_path / "no-port"), env={"PYTHONPATH": path})
    assert "Jupyter extension also named appmode is installed" in done.stderr, done.stderr
    assert "pip uninstall appmode" in done.stderr and "Traceback" not in done.stderr
