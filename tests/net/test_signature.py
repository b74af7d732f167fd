"""The car's host's signature (issue 80.5): a client hears what the host of its URL's id
signed, or the first host it met with its key (kept), over exactly what it said, in
answer to exactly what was asked."""

from __future__ import annotations

from pathlib import Path

import pytest

from tests.support.processes import run

pytest.importorskip("cryptography")


def test_the_first_host_met_is_kept_and_no_other_is_heard_after() -> None:
    from appmode.files import data_folder
    from appmode.net.signature import KNOWN_FILE, Signer, Trust

    car, forger = Signer("the room's host key"), Signer("a key holder's own")
    said = car.sign("sample", "appmode/car/events", b'{"t": "stopped"}', b"")
    assert Trust("key").holds(said, "sample", "appmode/car/events", b'{"t": "stopped"}', b"")
    assert car.id in (data_folder() / KNOWN_FILE).read_text()
    later = Trust("key")
    assert later.id == car.id and not later.strangers
    forged = forger.sign("sample", "appmode/car/events", b'{"t": "stopped"}', b"")
    assert not later.holds(forged, "sample", "appmode/car/events", b'{"t": "stopped"}', b"")
    assert later.strangers == {forger.id} and forger.id not in later.refusal()
    assert Trust("another key").id is None, "kept for its own key alone"


def test_a_signature_holds_for_what_was_said_and_asked_alone() -> None:
    from appmode.net.signature import Signer, Trust

    car = Signer("the room's host key")
    trust = Trust("key", car.id)
    said = car.sign("reply", "appmode/car/stop", '{"confirmed": true}', b"vm 1a2b", b"")
    assert trust.holds(said, "reply", "appmode/car/stop", '{"confirmed": true}', b"vm 1a2b", b"")
    for other in (
        ("reply", "appmode/car/stop", '{"confirmed": true}', b"vm 9f9f", b""),  # replayed
        ("reply", "appmode/car/stop", '{"confirmed": 1}', b"vm 1a2b", b""),  # altered
        ("reply", "appmode/car-2/stop", '{"confirmed": true}', b"vm 1a2b", b""),
    ):
        assert not trust.holds(said, *other), other
    for garbage in (None, "", "x y", said.split(" ")[0], said + "A", f"{car.id} !!!!"):
        assert not trust.holds(garbage, "reply", "appmode/car/stop"), garbage


def test_a_bad_host_id_is_one_line(tmp_path: Path) -> None:
    url = "zenoh://car?connect=tcp/127.0.0.1:9&key=k&id=short"
    for args in (("params", url), ("fleet", "--key", "k", "--id", "short")):
        done = run(*args)
        (line,) = done.stderr.strip().splitlines()
        assert done.returncode == 2 and "is no host id" in line and "Traceback" not in line, line
