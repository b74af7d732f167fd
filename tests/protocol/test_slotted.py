"""The events and table rows as values: equality, repr, hashing, immutability, copies."""

from __future__ import annotations

import copy
import pickle

import pytest

from appmode.protocol import control
from appmode.protocol.app import (
    Attitude,
    BadFrame,
    Garbage,
    Move,
    ParamsRecord,
    ReadParams,
    SaveParams,
    SetParam,
    Stop,
    Velocity,
)
from appmode.protocol.directions import MOTIONS
from appmode.protocol.layouts import SCALED, VELOCITY


def test_equal_by_class_and_shown_fields_not_by_raw() -> None:
    assert Velocity(1, 2, 3, raw=b"{A1:2:3:0}$") == Velocity(1, 2, 3)
    assert Velocity(1, 2, 3, terminated=False) == Velocity(1, 2, 3)
    assert Velocity(1, 2, 3) != Velocity(1, 2, 4)
    assert Velocity(1, 2, 3, 0) != Attitude(1, 2, 3, 0)
    assert Move(1) != Move(1, numeric=True)
    assert ReadParams() != SaveParams()  # the same fields, two frames
    assert Stop(b"Z") == Stop()
    assert Garbage(b"x") != Garbage(b"y")  # an error event's bytes are what it is
    assert BadFrame(b"{x}", "unknown frame") != BadFrame(b"{x}", "other")
    assert Move(1) != (1, False, b"")
    assert control.Reply(0x41, 500, b"#A") == control.Reply(0x41, 500)
    assert control.Garbage(b"x") != Garbage(b"x")  # the two ports' garbage are not one type


def test_repr_shows_the_fields_and_not_raw() -> None:
    assert repr(Velocity(0, 500, 0, raw=b"{A0:500:0:0}$")) == "Velocity(x=0, y=500, z=0, extra=0)"
    assert repr(Stop(b"Z")) == "Stop()"
    assert repr(Garbage(b"xx")) == "Garbage(raw=b'xx')"
    assert repr(SetParam(0, 800, b"{0:800}")) == "SetParam(index=0, value=800)"
    assert repr(control.PositionFrame(1, 2, 3, b"\xff")) == "PositionFrame(x=1, y=2, z=3)"


def test_commands_and_rows_are_immutable_and_hashable() -> None:
    move = Move(3, raw=b"C")
    with pytest.raises(AttributeError, match="immutable"):
        move.direction = 4
    with pytest.raises(AttributeError, match="immutable"):
        del move.raw
    assert move.direction == 3
    assert {Move(3), Move(3, raw=b"C"), Stop()} == {Move(3), Stop()}
    assert hash(SCALED) == hash(copy.copy(SCALED))
    with pytest.raises(AttributeError, match="immutable"):
        VELOCITY.scale = 2.0


def test_records_are_not_hashable() -> None:
    with pytest.raises(TypeError):
        hash(Velocity(1, 2, 3))


@pytest.mark.parametrize(
    "value",
    [
        Move(2, numeric=True, raw=b"\x02"),
        Stop(b"Z"),
        SetParam(1, 100, b"{1:100}"),
        ReadParams(0x3B, b"{Q;P}"),
        Velocity(1, -2, 3, 4, terminated=False, raw=b"{A1:-2:3:4}"),
        ParamsRecord((1, 2, 3, 4, 5, 6, 7, 8, 9), raw=b"{C...}$"),
        MOTIONS["forward"],
        SCALED,
        control.VelocityFrame(1, -2, 3, angle=True, raw=b"\xff\xfe\x01"),
        control.EncoderReport((1, 2, 3, 4), (5, 6, 7, 8), raw=b"$"),
        control.Garbage(b"\x00", "bytes outside any frame"),
    ],
)
def test_copies_and_pickles_keep_every_field(value: object) -> None:
    for twin in (copy.copy(value), copy.deepcopy(value), pickle.loads(pickle.dumps(value))):
        assert type(twin) is type(value)
        fields = value._fields  # type: ignore[attr-defined]
        assert fields and all(getattr(twin, f) == getattr(value, f) for f in fields)


def test_patterns_match_fields_in_constructor_order() -> None:
    match Velocity(7, 8, 9):
        case Velocity(x, y, z):
            assert (x, y, z) == (7, 8, 9)
        case _:
            pytest.fail("no match")
    match SetParam(0, 800):
        case SetParam(index, value):
            assert (index, value) == (0, 800)
        case _:
            pytest.fail("no match")
