"""appmode as the car's Bluetooth module, for a phone: `appmode board --advertise` and
`appmode tap advertise:NAME`, registered with the BlueZ stand-in (GattManager1,
LEAdvertisingManager1, a server-role Profile1). A bleak program that knows nothing of
appmode stands in for the phone's app. Judged on the boards' recordings."""

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
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

import pytest

from appmode.bluetooth.availability import unsupported
from appmode.bluetooth.standin.bus import PrivateBus
from appmode.testing.served import ServedBoard
from appmode.transcript.reading import read_transcript
from tests.support.processes import appmode_cmd, board_process, run, sent_lines, wait_for

NAME = "appmode-car"
PHONE = textwrap.dedent(
    """
    import asyncio, sys
    from bleak import BleakClient, BleakScanner

    UART = "0000ffe1-0000-1000-8000-00805f9b34fb"

    async def until(got, wanted, seconds=5.0):
        for _ in range(int(seconds / 0.02)):
            if wanted(bytes(got)):
                return
            await asyncio.sleep(0.02)
        raise SystemExit(f"not heard in time; heard {bytes(got)[-200:]!r}")

    def record(got, start):
        at = got.find(b"{C", start)
        return bytes(got[at:got.index(b"$", at) + 1]).decode()

    async def main(name, how):
        device = await BleakScanner.find_device_by_name(name, timeout=10)
        assert device is not None, f"{name} not found"
        got = bytearray()
        client = BleakClient(device)
        await client.connect()
        if how == "pair":
            await client.pair()
        await client.start_notify(UART, lambda _, data: got.extend(data))
        send = lambda data: client.write_gatt_char(UART, data, response=False)
        await send(b"{Q:P}")
        await until(got, lambda b: b"{C" in b and b.find(b"$", b.find(b"{C")) > 0)
        print(record(got, 0), flush=True)
        mark = len(got)
        await send(b"{1:1234}")
        await asyncio.sleep(0.2)
        await send(b"{Q:P}")
        await until(got, lambda b: b"{C" in b[mark:] and b.find(b"$", b.find(b"{C", mark)) > 0)
        print(record(got, mark), flush=True)
        await send(b"A")
        await asyncio.sleep(0.6)
        if how == "vanish":  # mid-drive, a frame open: the app dies, the phone drops it
            await send(b"{1:20")
            print("driving", flush=True)
            await asyncio.sleep(60)
        await send(b"Z")
        await asyncio.sleep(0.3)
        await client.disconnect()

    asyncio.run(main(sys.argv[1], sys.argv[2]))
    """
)


@pytest.fixture
def phone(tmp_path: Path) -> Path:
    script = tmp_path / "phone.py"
    script.write_text(PHONE)
    return script


def car_heard(board: ServedBoard) -> list[str]:
    """What the car behind the stand-in received, unit by unit."""
    return [e.data.decode() for e in board.recording().entries if e.direction == ">"]


@contextmanager
def tapping(car: ServedBoard, record: Path) -> Iterator[subprocess.Popen[str]]:
    """`appmode tap advertise:NAME` between a phone to come and `car`, its port line read;
    killed at the end if still running."""
    assert car.ble is not None
    tap = subprocess.Popen(
        appmode_cmd("tap", f"advertise:{NAME}", car.ble, "--record", str(record)),
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    try:
        assert tap.stdout is not None
        assert tap.stdout.readline().strip() == f"port: ble://{NAME}"
        yield tap
    finally:
        if tap.poll() is None:
            tap.kill()
            tap.communicate()


def run_phone(script: Path, how: str = "drive") -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, str(script), NAME, how],
        capture_output=True,
        text=True,
        timeout=90,
        check=False,
    )


def test_a_bleak_program_finds_the_advertised_car_reads_sets_and_drives_it(
    appmode_ble_board: ServedBoard, phone: Path, tmp_path: Path
) -> None:
    record = tmp_path / "advertised.transcript"
    with board_process("--advertise", NAME, "--record", str(record)) as board:
        assert board.url == f"ble://{NAME}"
        assert board.details["ble"].startswith(f"advertised as {NAME} (FFE0)")
        done = run_phone(phone)
        err = board.stop(signal.SIGINT)
    assert done.returncode == 0, done.stderr
    before, after = done.stdout.split()
    assert before == "{C500:10000:20:0:10:10:10:0:0}$"
    assert after == "{C500:1234:20:0:10:10:10:0:0}$"  # the set, read back
    assert sent_lines(record) == ["{Q:P}", "{1:1234}", "{Q:P}", "A", "Z"]
    assert "a phone subscribed" in err and "the phone unsubscribed or left" in err
    assert car_heard(appmode_ble_board) == []  # the other car heard nothing
    assert f"WARNING: the module {NAME} takes any phone in range" in err


@pytest.mark.parametrize(
    ("admission", "how", "taken"),
    [
        (("--allow", "11:22:33:44:55:66"), "drive", False),
        (("--allow", "02:ca:40:00:00:01", "--allow", "11:22:33:44:55:66"), "drive", True),
        (("--secure",), "drive", False),
        (("--secure",), "pair", True),
    ],
    ids=["a stranger", "an allowed phone", "unpaired", "paired"],
)
def test_an_advertised_module_takes_only_the_phones_it_is_told_to(
    appmode_ble_board: ServedBoard,
    phone: Path,
    tmp_path: Path,
    admission: tuple[str, ...],
    how: str,
    taken: bool,
) -> None:
    """Issue 64.4: any phone in range could drive the car. The stand-in's central is
    02:CA:40:00:00:01; it pairs when the phone calls Pair."""
    record = tmp_path / "advertised.transcript"
    with board_process("--advertise", NAME, *admission, "--record", str(record)) as board:
        done = run_phone(phone, how)
        err = board.stop(signal.SIGINT)
    assert "WARNING" not in err
    if taken:
        assert done.returncode == 0, done.stderr
        assert sent_lines(record) == ["{Q:P}", "{1:1234}", "{Q:P}", "A", "Z"]
    else:
        assert done.returncode != 0 and "not heard in time" in done.stderr
        assert sent_lines(record) == [], "the board heard nothing of that phone"


def test_tap_advertise_warns_of_any_phone_and_refuses_options_elsewhere(tmp_path: Path) -> None:
    done = run("tap", "pty", "sim://", "--allow", "11:22:33:44:55:66", "--record",
               str(tmp_path / "t.transcript"))  # fmt: skip
    assert done.returncode == 2
    assert "--allow and --secure are for an advertised app side" in done.stderr
    bad = run("board", "--advertise", NAME, "--allow", "not-an-address")
    assert bad.returncode == 2 and "is not a Bluetooth address" in bad.stderr


def test_scan_lists_the_advertised_module_and_params_reach_it_over_spp_and_ble(
    appmode_ble_board: ServedBoard, tmp_path: Path
) -> None:
    record = tmp_path / "advertised.transcript"
    with board_process("--advertise", NAME, "--nus", "--record", str(record)) as board:
        assert "(Nordic UART)" in board.details["ble"]
        found = run("scan", "--time", "1", "--json")
        assert found.returncode == 0, found.stderr
        rows = [json.loads(line) for line in found.stdout.splitlines()]
        mine = {row["kind"]: row for row in rows if row["name"] == NAME}
        assert mine["ble"]["service"] == "Nordic UART"
        for kind in ("spp", "ble"):
            done = run("params", mine[kind]["url"])
            assert done.returncode == 0, done.stderr
            assert "max_position            10000" in done.stdout
        err = board.stop()
    assert sent_lines(record).count("{Q:P}") >= 2
    assert "spp: a phone connected" in err
    assert re.search(r"spp: (the phone closed the link|the link broke)", err), err


def test_tap_records_the_phone_and_the_car_and_stops_the_car_when_the_phone_vanishes(
    appmode_ble_board: ServedBoard, phone: Path, tmp_path: Path
) -> None:
    record = tmp_path / "tap.transcript"
    with tapping(appmode_ble_board, record) as tap:
        driver = subprocess.Popen(
            [sys.executable, str(phone), NAME, "vanish"],
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            text=True,
        )
        assert driver.stdout is not None
        for _ in range(3):  # two C records, then "driving": A sent, a frame left open
            line = driver.stdout.readline()
        assert line.strip() == "driving", driver.communicate()
        time.sleep(0.3)
        driver.kill()  # the phone's app dies mid-drive
        driver.communicate()
        _, err = tap.communicate(timeout=20)
    assert tap.returncode == 0, err
    assert re.search(r"the app side left: the phone left the BLE link \(.*\); the board got Z", err)
    # the transcript: both directions, who left, the stop last
    transcript = read_transcript(record)
    assert transcript.title == f"tap: advertise:{NAME} <-> {appmode_ble_board.ble}"
    text = record.read_text()
    assert "# the app side left at" in text
    assert sent_lines(record) == ["{Q:P}", "{1:1234}", "{Q:P}", "A", "{1:20", "{}", "Z"]
    assert any(e.direction == "<" and e.data.startswith(b"{C") for e in transcript.entries)
    # the car's own recording: it got what the phone sent, then the stop
    assert car_heard(appmode_ble_board) == ["{Q:P}", "{1:1234}", "{Q:P}", "A", "{1:20", "{}", "Z"]
    state = appmode_ble_board.wait_until(lambda s: not s.moving, what="a stop")
    assert state.params["max_position"] == 1234


def test_a_car_whose_program_ends_leaves_the_phone_it_served(
    appmode_ble_board: ServedBoard, tmp_path: Path
) -> None:
    script = tmp_path / "hold.py"
    script.write_text(
        textwrap.dedent(
            f"""
            import asyncio
            from bleak import BleakClient, BleakScanner

            async def main():
                device = await BleakScanner.find_device_by_name("{NAME}", timeout=10)
                lost = asyncio.Event()
                async with BleakClient(device, disconnected_callback=lambda _: lost.set()) as c:
                    await c.start_notify("0000ffe1-0000-1000-8000-00805f9b34fb", lambda *_: 0)
                    print("connected", flush=True)
                    await asyncio.wait_for(lost.wait(), 20)
                    print("lost", flush=True)

            asyncio.run(main())
            """
        )
    )
    with board_process("--advertise", NAME) as board:
        holder = subprocess.Popen([sys.executable, str(script)], stdout=subprocess.PIPE, text=True)
        assert holder.stdout is not None
        assert holder.stdout.readline().strip() == "connected"
        board.stop()
        out, _ = holder.communicate(timeout=30)
    assert out.strip() == "lost"
    wait_for(lambda: any("what it registered is gone" in line for line in appmode_ble_board.log))


def test_advertise_without_bluez_says_so_in_one_line(tmp_path: Path) -> None:
    with PrivateBus() as bus:  # a bus, but no BlueZ on it
        done = run("board", "--advertise", env={"DBUS_SYSTEM_BUS_ADDRESS": bus.address})
        tapped = run(
            "tap",
            "advertise",
            "sim://",
            "--record",
            str(tmp_path / "t.transcript"),
            env={"DBUS_SYSTEM_BUS_ADDRESS": bus.address},
        )
    for failed in (done, tapped):
        assert failed.returncode != 0
        lines = failed.stderr.strip().splitlines()
        assert len(lines) == 1, failed.stderr
        assert "no Bluetooth here" in lines[0] and "org.bluez is not on the bus" in lines[0]
    assert not (tmp_path / "t.transcript").exists()


@pytest.mark.parametrize(("platform", "named"), [("darwin", "macOS"), ("win32", "Windows")])
def test_elsewhere_than_linux_advertising_is_refused_in_a_line(
    monkeypatch: pytest.MonkeyPatch, platform: str, named: str
) -> None:
    monkeypatch.setattr(sys, "platform", platform)
    monkeypatch.setattr(os, "name", "nt" if platform == "win32" else "posix")
    why = unsupported()
    assert why is not None and named in why and "Linux" in why and "\n" not in why


MUTE_PHONE = textwrap.dedent(
    f"""
    import asyncio
    from bleak import BleakClient, BleakScanner

    async def main():
        device = await BleakScanner.find_device_by_name("{NAME}", timeout=10)
        async with BleakClient(device) as client:  # writes, never subscribes
            await client.write_gatt_char("0000ffe1-0000-1000-8000-00805f9b34fb", b"JA",
                                         response=False)
            await asyncio.sleep(0.5)

    asyncio.run(main())
    """
)


def test_tap_sees_a_phone_that_never_subscribed_leave_and_stops_the_car(
    appmode_ble_board: ServedBoard, tmp_path: Path
) -> None:
    record = tmp_path / "tap.transcript"
    script = tmp_path / "mute.py"
    script.write_text(MUTE_PHONE)
    with tapping(appmode_ble_board, record) as tap:
        done = subprocess.run(
            [sys.executable, str(script)], capture_output=True, text=True, timeout=60, check=False
        )
        assert done.returncode == 0, done.stderr
        _, err = tap.communicate(timeout=20)
    assert tap.returncode == 0, err
    assert "the app side left: the phone left the BLE link (the phone disconnected)" in err
    assert sent_lines(record) == ["J", "A", "Z"]
    assert car_heard(appmode_ble_board) == ["J", "A", "Z"]
    appmode_ble_board.wait_until(lambda s: not s.moving, what="a stop")


def test_the_advertised_module_takes_one_phone_at_a_time(
    appmode_ble_board: ServedBoard, tmp_path: Path
) -> None:
    from dbus_fast import Message, MessageType, Variant
    from dbus_fast.aio import MessageBus

    record = tmp_path / "advertised.transcript"

    async def write(bus: MessageBus, owner: str, device: str, data: bytes) -> Message:
        reply = await bus.call(
            Message(
                destination=owner,
                path="/org/appmode/module/service0/char0",
                interface="org.bluez.GattCharacteristic1",
                member="WriteValue",
                signature="aya{sv}",
                body=[data, {"device": Variant("o", device)}],
            )
        )
        assert reply is not None
        return reply

    async def two_phones() -> tuple[Message, Message]:
        bus = await MessageBus(bus_address=appmode_ble_board.bus).connect()
        owner = next(
            line.rsplit(" ", 1)[1] for line in appmode_ble_board.log if "advertised by" in line
        )
        first = await write(bus, owner, "/org/bluez/hci0/dev_02_00_00_00_00_0A", b"A")
        second = await write(bus, owner, "/org/bluez/hci0/dev_02_00_00_00_00_0B", b"B")
        bus.disconnect()
        return first, second

    with board_process("--advertise", NAME, "--record", str(record)) as board:
        wait_for(lambda: any("advertised by" in line for line in appmode_ble_board.log))
        first, second = asyncio.run(two_phones())
        wait_for(lambda: sent_lines(record) == ["A"])
        err = board.stop()
    assert first.message_type == MessageType.METHOD_RETURN
    assert second.message_type == MessageType.ERROR
    assert second.error_name == "org.bluez.Error.NotPermitted"
    assert "held by /org/bluez/hci0/dev_02_00_00_00_00_0A" in err


def test_an_advertised_name_must_fit_an_advertisement(tmp_path: Path) -> None:
    done = run("board", "--advertise", "a-name-too-long-to-advertise")
    assert done.returncode == 2 and "an advertised name fits 20 at most" in done.stderr
    done = run("tap", "advertise:bad\tname", "sim://", "--record", str(tmp_path / "t"))
    assert done.returncode == 2 and "is not a name to advertise" in done.stderr
    assert not (tmp_path / "t").exists()
