"""The simulated car as a Bluetooth module behind the BlueZ stand-in, reached as a user
would: a bleak program, `appmode scan`, and `ble://`/`bt://` in the commands. Each is
judged on the board's own recording."""

from __future__ import annotations

import asyncio
import json
import os
import re
import signal
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import pytest
import serial

import appmode.ports.urls  # noqa: F401 - registers ble:// and bt:// with pyserial
from appmode.testing.served import ServedBoard
from tests.support.processes import ROOT, appmode_cmd, run, scripted, wait_for

BLEAK_ONLY = textwrap.dedent(
    """
    import asyncio
    from bleak import BleakClient, BleakScanner

    async def main():
        device = await BleakScanner.find_device_by_name("HC-08", timeout=5)
        got = bytearray()
        async with BleakClient(device) as client:
            await client.start_notify("0000ffe1-0000-1000-8000-00805f9b34fb",
                                      lambda _, data: got.extend(data))
            await client.write_gatt_char("0000ffe1-0000-1000-8000-00805f9b34fb",
                                         b"{Q:P}", response=False)
            for _ in range(100):
                if b"{C" in got and got.endswith(b"$") and got.rfind(b"{C") < got.rfind(b"$"):
                    break
                await asyncio.sleep(0.02)
        start = got.rfind(b"{C")
        print(got[start:got.index(b"$", start) + 1].decode())

    asyncio.run(main())
    """
)


def sent(board: ServedBoard) -> bytes:
    return b"".join(e.data for e in board.recording().entries if e.direction == ">")


def test_a_bleak_program_that_knows_nothing_of_appmode_reads_the_parameters(
    appmode_ble_board: ServedBoard, tmp_path: Path
) -> None:
    script = tmp_path / "plain_bleak.py"
    script.write_text(BLEAK_ONLY)
    done = subprocess.run(
        [sys.executable, str(script)], capture_output=True, text=True, timeout=60, check=False
    )
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == "{C500:10000:20:0:10:10:10:0:0}$"
    assert b"{Q:P}" in sent(appmode_ble_board)


def test_scan_lists_the_ble_module_and_the_paired_classic_one(
    appmode_ble_board: ServedBoard,
) -> None:
    done = run("scan", "--time", "1", "--json")
    assert done.returncode == 0, done.stderr
    assert [line for line in done.stdout.splitlines() if '"ble"' in line or '"spp"' in line]
    assert appmode_ble_board.ble is not None and appmode_ble_board.spp is not None
    assert f'"url": "{appmode_ble_board.ble}"' in done.stdout
    assert f'"url": "{appmode_ble_board.spp}"' in done.stdout
    table = run("scan", "--time", "1")
    assert "HC-08" in table.stdout and "FFE0" in table.stdout and "paired" in table.stdout


@pytest.mark.parametrize("which", ["ble", "spp"])
def test_params_reads_the_nine_parameters(appmode_ble_board: ServedBoard, which: str) -> None:
    url = getattr(appmode_ble_board, which)
    done = run("params", url)
    assert done.returncode == 0, done.stderr
    assert "max_speed                 500" in done.stdout
    assert "system_mode" in done.stdout
    wait_for(lambda: sent(appmode_ble_board).endswith(b"Z"), 5)
    assert b"{Q:P}" in sent(appmode_ble_board)


@pytest.mark.parametrize("which", ["ble", "spp"])
def test_a_driving_script_moves_the_car_and_ends_with_z(
    appmode_ble_board: ServedBoard, which: str
) -> None:
    url = getattr(appmode_ble_board, which)
    done = run("drive", url, stdin=b"drive A\nwait 0.8\n")
    assert done.returncode == 0, done.stderr
    wait_for(lambda: sent(appmode_ble_board).endswith(b"Z"), 5)
    assert b"A" in sent(appmode_ble_board)
    appmode_ble_board.wait_until(lambda s: not s.moving, what="a stopped car")


def driving(board: ServedBoard) -> subprocess.Popen[str]:
    """`appmode drive` over the board's BLE module, driving forward (script mode) until
    it is stopped; the board moving."""
    assert board.ble is not None
    proc = scripted(board.ble, "drive A\nwait 60\n")
    try:
        board.wait_until(lambda s: s.moving, timeout=15, what="a moving car")
    except BaseException:
        proc.kill()
        proc.communicate()
        raise
    return proc


def test_sigterm_mid_drive_leaves_z_last(appmode_ble_board: ServedBoard) -> None:
    proc = driving(appmode_ble_board)
    proc.send_signal(signal.SIGTERM)
    proc.communicate(timeout=15)
    wait_for(lambda: sent(appmode_ble_board).endswith(b"Z"), 5)
    appmode_ble_board.wait_until(lambda s: not s.moving, what="a stopped car")


def _drop(bus: str) -> None:
    """Ask the stand-in to drop its connections (the car out of range)."""
    _ask(bus, "Drop")


def _ask(bus: str, member: str, *args: str) -> None:
    """Call one of the stand-in's own methods (what no radio API has)."""
    from dbus_fast import Message, MessageType
    from dbus_fast.aio import MessageBus

    async def call() -> None:
        link = await MessageBus(bus_address=bus).connect()
        reply = await link.call(
            Message(
                destination="org.bluez",
                path="/org/appmode/standin",
                interface="org.appmode.StandIn1",
                member=member,
                signature="s" * len(args),
                body=list(args),
            )
        )
        link.disconnect()
        assert reply is not None and reply.message_type == MessageType.METHOD_RETURN

    asyncio.run(call())


def test_a_module_s_name_opens_it_and_two_of_one_name_are_refused(
    appmode_ble_board: ServedBoard,
) -> None:
    """Issue 64.6: with two `HC-08` nearby, `ble://HC-08` opened the first one heard."""
    board = appmode_ble_board
    assert board.bus is not None
    done = run("params", "ble://HC-08")
    assert done.returncode == 0 and "max_speed" in done.stdout, done.stderr
    _ask(board.bus, "Nearby", "")
    before = len(sent(board))
    done = run("params", "ble://HC-08")
    assert done.returncode != 0
    lines = done.stderr.strip().splitlines()
    assert len(lines) == 1, done.stderr
    assert "2 BLE devices nearby are called 'HC-08'" in lines[0]
    assert "02:CA:40:00:00:08" in lines[0] and "02:CA:40:00:01:00" in lines[0]
    assert "ble://02:CA:40:00:00:08" in lines[0]
    assert len(sent(board)) == before, "nothing was sent to either"
    done = run("params", board.ble)
    assert done.returncode == 0, "by its address it opens"


def test_a_dropped_link_is_lost_then_retried_and_z_goes_first(
    appmode_ble_board: ServedBoard,
) -> None:
    board = appmode_ble_board
    assert board.bus is not None
    proc = driving(board)
    try:
        before = len(sent(board))
        _drop(board.bus)
        wait_for(lambda: len(sent(board)) > before, 15)  # reconnected, and sent
        assert sent(board)[before : before + 1] == b"Z"
        board.wait_until(lambda s: not s.moving, what="a stopped car")
    finally:
        proc.send_signal(signal.SIGTERM)
        out, err = proc.communicate(timeout=15)
    assert "lost" in out + err and "is back" in out + err


def test_a_burst_larger_than_the_modules_buffer_is_paced_not_lost(
    appmode_ble_board: ServedBoard,
) -> None:
    port = serial.serial_for_url(appmode_ble_board.ble, timeout=0.1)
    started = time.monotonic()
    port.write(b"J" * 600)  # 600 bytes: more than four of the module's buffers
    port.close()  # what was written goes first
    took = time.monotonic() - started
    wait_for(lambda: sent(appmode_ble_board).count(b"J") >= 600, 10)
    assert sent(appmode_ble_board).count(b"J") == 600
    assert took >= 600 / 960 * 0.9  # never faster than the module's UART


COMMANDS = [
    ("params", "ble://HC-08"),
    ("params", "bt://02:CA:40:00:00:05"),
    ("monitor", "ble://02:CA:40:00:00:08", "--count", "1"),
    ("scan", "--time", "1"),
    ("drive", "ble://HC-08"),
]


@pytest.mark.parametrize("command", COMMANDS, ids=lambda c: " ".join(c[:2]))
def test_without_bluez_each_command_says_so_in_one_line(
    command: tuple[str, ...], tmp_path: Path
) -> None:
    started = time.monotonic()
    done = run(*command, env={"DBUS_SYSTEM_BUS_ADDRESS": f"unix:path={tmp_path}/no-bus"})
    assert time.monotonic() - started < 10
    assert done.returncode != 0
    lines = done.stderr.strip().splitlines()
    assert len(lines) == 1 and "no Bluetooth here" in lines[0], done.stderr
    assert "Traceback" not in done.stderr
    assert os.environ.get("DBUS_SYSTEM_BUS_ADDRESS") != f"unix:path={tmp_path}/no-bus"


@pytest.mark.slow
def test_scan_probe_names_the_firmware_and_doctor_checks_the_modules(
    appmode_ble_board: ServedBoard,
) -> None:
    done = run("scan", "--time", "1", "--probe")
    assert done.returncode == 0, done.stderr
    rows = {line.split()[0]: line.split()[-1] for line in done.stdout.splitlines()[1:]}
    assert rows == {"ble": "sheet", "spp": "sheet"}
    doctor = run("doctor")
    assert f"ok {appmode_ble_board.ble}: this is a car" in doctor.stdout
    assert f"ok {appmode_ble_board.spp}: this is a car" in doctor.stdout
    assert doctor.returncode == 0
    sent_now = sent(appmode_ble_board)
    assert set(sent_now.replace(b"{Q:P}", b"")) <= set(b"Z")  # only reads, and stops


def test_ctrl_c_ends_a_scan_cleanly(appmode_ble_board: ServedBoard) -> None:
    proc = subprocess.Popen(
        appmode_cmd("scan", "--time", "30"),
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        cwd=ROOT,
    )
    time.sleep(2)
    proc.send_signal(signal.SIGINT)
    _, err = proc.communicate(timeout=10)
    assert proc.returncode == 130
    assert "Traceback" not in err


def kill_bus(bus: str) -> None:
    """Kill the stand-in's dbus-daemon: the module is gone for good (its link never
    comes back)."""
    daemons = bus_processes(bus, watcher=False)
    assert daemons, f"no dbus-daemon serves {bus}"
    os.kill(daemons[0], signal.SIGKILL)


def bus_processes(bus: str, watcher: bool = True) -> list[int]:
    """The processes serving `bus`: its dbus-daemon, and (`watcher`) the shell that
    stops it once appmode is gone."""
    folder = bus_folder(bus)
    wanted = f"--config-file={folder}/bus.conf".encode()
    found = []
    for entry in Path("/proc").iterdir():
        try:
            words = (entry / "cmdline").read_bytes().split(b"\0")
        except OSError:
            continue
        if wanted in words and (watcher or words[0].endswith(b"dbus-daemon")):
            found.append(int(entry.name))
    return found


def board_bluetooth(start_new_session: bool = False) -> tuple[subprocess.Popen[str], str]:
    """`appmode board --bluetooth` started, and the bus it says it serves."""
    proc = subprocess.Popen(
        appmode_cmd("board", "--bluetooth"),
        stdout=subprocess.PIPE,
        stderr=subprocess.DEVNULL,
        text=True,
        cwd=ROOT,
        start_new_session=start_new_session,
    )
    assert proc.stdout is not None
    for line in proc.stdout:
        if line.startswith("bus: "):
            return proc, line.split(": ", 1)[1].strip()
    proc.kill()
    raise AssertionError(f"board --bluetooth said no bus: {proc.wait(10)}")


def bus_folder(bus: str) -> Path:
    return Path(bus.split("path=", 1)[1].split(",", 1)[0]).parent


def test_board_bluetooth_killed_leaves_no_daemon_and_its_folder_goes_next_time() -> None:
    """Issue 64.10: SIGKILL of `board --bluetooth` left its dbus-daemon running and its
    folder behind."""
    from appmode.bluetooth.standin.bus import PrivateBus

    proc, bus = board_bluetooth()
    try:
        assert bus_processes(bus, watcher=False)
    finally:
        proc.kill()
        proc.wait(10)
    wait_for(lambda: not bus_processes(bus), 5)
    assert bus_folder(bus).exists(), "left behind by a killed owner"
    with PrivateBus():
        assert not bus_folder(bus).exists(), "removed by the next bus started"


def test_a_link_lost_for_good_is_never_shown_as_a_stop(appmode_ble_board: ServedBoard) -> None:
    """Issue 64.2: the module gone for good, the car still moving on its last letter:
    the panel says it may be moving, and `drive` ends non-zero saying the final stop was
    not delivered."""
    board = appmode_ble_board
    assert board.bus is not None and board.ble is not None
    proc = scripted(board.ble, "drive A\nwait 4\nstatus\nquit\n")
    try:
        board.wait_until(lambda s: s.moving, timeout=15, what="a moving car")
        kill_bus(board.bus)
        out, err = proc.communicate(timeout=30)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.communicate()
    assert proc.returncode == 1, (out, err)
    assert "appmode: the final stop was not delivered: the car may still be moving" in err, err
    assert "Traceback" not in err
    assert "NOT STOPPED" in out and "Z stop" not in out, out
    assert board.state.moving and sent(board).endswith(b"A"), "the board's own record"


HOSTILE = "\x1b]52;c;aGk=\x07\x1b[2K\rHC-08\x1b[8m"
"""A nearby device's name that writes the clipboard, erases the line and hides the rest
(issue 64.5), when a terminal is given it as it is."""


def test_scan_shows_a_hostile_device_name_escaped(appmode_ble_board: ServedBoard) -> None:
    assert appmode_ble_board.bus is not None
    _ask(appmode_ble_board.bus, "Nearby", HOSTILE)
    done = run("scan", "--time", "2")
    assert done.returncode == 0, done.stderr
    out = done.stdout + done.stderr
    assert not set(out) & {"\x1b", "\x07", "\r"}, repr(out)
    row = next(line for line in done.stdout.splitlines() if "02:CA:40:00:01:00" in line)
    assert "\\x1b]52;c;aGk=\\x07\\x1b[2K\\x0dHC-08\\x1b[8m" in row
    assert "ble://02:CA:40:00:01:00" in row, "the address and URL are shown"
    listed = run("scan", "--time", "2", "--json")
    names = [json.loads(line)["name"] for line in listed.stdout.splitlines()]
    assert HOSTILE in names and "\x1b" not in listed.stdout


@pytest.mark.parametrize("kind", ["ble", "spp"])
def test_what_the_user_sees_while_driving_over_each_link_kind(
    appmode_ble_board: ServedBoard, kind: str
) -> None:
    """Issue 69.1: over bt:// the console showed 2–4 records/s and y 0 while the board
    drove (the port said 1 byte waiting whatever it held: a byte a pass). What the user
    sees: the stream at the board's rate and the velocity it reports."""
    url = appmode_ble_board.ble if kind == "ble" else appmode_ble_board.spp
    assert url is not None
    started = time.monotonic()
    done = run("drive", url, stdin=b"drive A\nwait 2\nstatus\nquit\n")
    took = time.monotonic() - started
    assert done.returncode == 0, done.stderr
    rate = re.search(r"link up\s+(\d+) records/s", done.stdout)
    assert rate is not None and int(rate.group(1)) >= 15, done.stdout
    assert re.search(r"velocity\s+x\s+0\s+y\s+500\s+z\s+0", done.stdout), done.stdout
    assert took < 8, took


def test_scan_shows_its_progress_on_a_terminal_and_not_in_a_pipe(
    appmode_ble_board: ServedBoard,
) -> None:
    """Issue 69.7: a long job shows what it waits for on a terminal, and stays quiet
    when piped."""
    from tests.support.terminal import stderr_on_a_terminal

    status, shown = stderr_on_a_terminal("scan", "--time", "2")
    assert status == 0
    assert "scanning" in shown and "/2 s:" in shown and " heard" in shown, shown
    assert shown.endswith("\r\x1b[K"), "the progress line is cleared"
    piped = run("scan", "--time", "2")
    assert "scanning" not in piped.stderr and "\r" not in piped.stderr


@pytest.mark.parametrize("how", ["hangup", "watcher killed"])
def test_no_dbus_daemon_outlives_its_board_however_it_ends(how: str) -> None:
    """Issue 80.13: dbus-daemon processes outlived `board --bluetooth` with parent 1: a
    hangup to the process group (a closed terminal) ended the watcher shell, and the
    daemon takes SIGHUP as "reload"; a watcher killed alone left it too."""
    proc, bus = board_bluetooth(start_new_session=True)  # a group, as a terminal's job
    try:
        daemons = bus_processes(bus, watcher=False)
        watchers = [pid for pid in bus_processes(bus) if pid not in daemons]
        assert daemons and watchers, (daemons, watchers)
        if how == "hangup":
            os.killpg(proc.pid, signal.SIGHUP)
        else:
            for pid in watchers:
                os.kill(pid, signal.SIGKILL)
        wait_for(lambda: not any(Path(f"/proc/{pid}").exists() for pid in daemons), 5)
    finally:
        proc.kill()
        proc.wait(10)
    wait_for(lambda: not bus_processes(bus), 5)
