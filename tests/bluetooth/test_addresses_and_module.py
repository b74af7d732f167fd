"""`ble://` and `bt://` URLs, and the module model the stand-in and the links pace by."""

from __future__ import annotations

import threading

import pytest

from appmode.bluetooth.inbox import RECEIVE_BUFFER, Inbox
from appmode.bluetooth.links.ble_port import BleSerial
from appmode.bluetooth.module import INPUT_BUFFER, PAYLOAD, UART_BYTES_PER_S, ModuleModel
from appmode.bluetooth.uuids import UART_SERVICES, full, uart_service
from appmode.errors import AppmodeError
from appmode.ports.radio import BleTarget, BtTarget
from appmode.ports.target import parse_target


def ble(url: str) -> BleTarget:
    radio = parse_target(url).radio
    assert isinstance(radio, BleTarget)
    return radio


def bt(url: str) -> BtTarget:
    radio = parse_target(url).radio
    assert isinstance(radio, BtTarget)
    return radio


def test_ble_urls_name_an_address_a_macos_uuid_or_a_name() -> None:
    assert ble("ble://aa:bb:cc:dd:ee:ff").address == "AA:BB:CC:DD:EE:FF"
    mac_uuid = "ble://0c4a7e2b-9f3d-4f7a-8b1e-2d6c5a4b3c21"
    assert ble(mac_uuid).address == "0C4A7E2B-9F3D-4F7A-8B1E-2D6C5A4B3C21"
    named = ble("ble://My%20Car")
    assert (named.address, named.name, named.service) == (None, "My Car", None)


def test_a_named_service_needs_all_three_uuids() -> None:
    target = ble("ble://HC-08?service=fff0&write=fff2&notify=fff1")
    assert target.service == (full("fff0"), full("fff2"), full("fff1"))
    with pytest.raises(AppmodeError, match="give write, notify too"):
        ble("ble://HC-08?service=fff0")
    with pytest.raises(AppmodeError, match="not a UUID"):
        ble("ble://HC-08?service=zz&write=fff2&notify=fff1")
    with pytest.raises(AppmodeError, match="unknown option 'baud'"):
        ble("ble://HC-08?baud=9600")


def test_bt_urls_take_an_address_and_a_channel() -> None:
    assert bt("bt://02:ca:40:00:00:05").channel == 1
    assert bt("bt://02:CA:40:00:00:05?channel=3").channel == 3
    for bad in ("bt://HC-05", "bt://02:CA:40:00:00:05?channel=31", "bt://"):
        with pytest.raises(AppmodeError):
            bt(bad)


def test_known_uart_services_are_recognised_among_others() -> None:
    assert uart_service(["00001800-0000-1000-8000-00805f9b34fb", full("FFE0")]) is UART_SERVICES[0]
    nordic = "6E400001-B5A3-F393-E0A9-E50E24DCCA9E"
    assert uart_service([nordic]) is UART_SERVICES[1]
    assert uart_service([full("180f")]) is None


def test_the_module_loses_what_overflows_its_buffer_and_drains_at_9600_bps() -> None:
    module = ModuleModel()
    burst = bytes(range(256)) * 2
    kept = module.from_radio(burst, 0.0)
    assert kept == burst[:INPUT_BUFFER]
    assert module.lost == len(burst) - INPUT_BUFFER
    # a second later the UART has sent 960 bytes: the buffer is empty again
    assert module.from_radio(burst[:INPUT_BUFFER], 1.0) == burst[:INPUT_BUFFER]
    # a writer paced at the UART's rate loses nothing
    paced = ModuleModel()
    for i in range(200):
        assert (
            paced.from_radio(b"x" * PAYLOAD, 10 + i * PAYLOAD / UART_BYTES_PER_S) == b"x" * PAYLOAD
        )
    assert paced.lost == 0


def test_notifications_are_cut_to_the_payload_a_few_per_connection_event() -> None:
    module = ModuleModel()
    record = b"{A0:0:0:0:0:0:100}$" * 10
    module.from_uart(record)
    sent = []
    while chunks := module.notifications():
        assert len(chunks) <= 4 and all(len(c) <= PAYLOAD for c in chunks)
        sent += chunks
    assert b"".join(sent) == record


def test_what_nobody_reads_is_bounded_the_newest_kept() -> None:
    port = BleSerial.__new__(BleSerial)  # the buffer alone: no radio
    port._ready = threading.Condition()
    port._received = Inbox(port._ready)
    for i in range(RECEIVE_BUFFER // 10):
        port._notified(None, bytearray(b"%010d" % i) * 2)
    assert len(port._received) == RECEIVE_BUFFER
    kept = port._received.read(2 * RECEIVE_BUFFER, 0, lambda: None)
    assert len(kept) == RECEIVE_BUFFER and kept.endswith(b"%010d" % (RECEIVE_BUFFER // 10 - 1))


def test_a_board_faster_than_the_radio_loses_what_overflows_the_module() -> None:
    from appmode.bluetooth.module import OUTPUT_BUFFER

    module = ModuleModel()
    module.from_uart(b"x" * (OUTPUT_BUFFER + 100))
    assert len(module.outgoing) == OUTPUT_BUFFER and module.lost == 100
