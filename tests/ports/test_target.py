"""A board's URL parsed once into a Target: what each layer reads of it."""

from __future__ import annotations

import pytest

from appmode.errors import AppmodeError
from appmode.ports.target import parse_target


def test_each_kind_of_url_is_told_apart() -> None:
    device = parse_target("/dev/ttyUSB0?baud=38400")
    assert (device.scheme, device.path, device.baud) == ("", "/dev/ttyUSB0", 38400)
    assert parse_target("COM3").path == "COM3"
    assert parse_target("socket://127.0.0.1:5000").network
    assert parse_target("rfc2217://[::1]:5000").network
    assert parse_target("ble://HC-08").radio and parse_target("bt://02:CA:40:00:00:05").radio
    sim = parse_target("sim://?profile=minibalance&drive=diff&port=uart2")
    assert sim.simulated and sim.profile == "minibalance" and sim.sim_port == "uart2"
    assert sim.sim_drive == "diff"
    assert str(sim) == sim.url


@pytest.mark.parametrize(
    ("url", "said"),
    [
        ("ftp://x", "unknown URL scheme 'ftp://'"),
        ("socket://localhost", "needs a host and a port"),
        ("sim://?colour=red", "unknown sim:// option 'colour'"),
        ("/dev/ttyUSB0?parity=E", "only ?baud=N is known"),
        ("/dev/ttyUSB0?baud=fast", "bad baud rate 'fast'"),
        ("?baud=9600", "empty port name"),
    ],
)
def test_a_bad_url_says_what_is_wrong_once_at_parsing(url: str, said: str) -> None:
    with pytest.raises(AppmodeError, match=said.replace("?", r"\?")):
        parse_target(url)


def test_a_command_s_options_fill_in_a_simulated_board_and_never_contradict_it() -> None:
    sim = parse_target("sim://?drive=diff")
    assert sim.with_sim(profile="minibalance", drive=None).url == (
        "sim://?drive=diff&profile=minibalance"
    )
    assert sim.with_sim(drive="diff") is sim
    with pytest.raises(AppmodeError, match="sets drive=diff, and --drive omni another"):
        sim.with_sim(drive="omni")
    device = parse_target("/dev/ttyUSB0")
    assert device.with_sim(profile="minibalance") is device
    assert device.for_uart2() is device
