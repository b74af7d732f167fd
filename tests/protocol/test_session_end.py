"""SessionEnd: the bytes that end a host session with the car stopped, on any board."""

from __future__ import annotations

import pytest

from appmode.protocol.session_end import SessionEnd


@pytest.mark.parametrize(
    ("sent", "stop"),
    [
        (b"", b"Z"),
        (b"JA", b"Z"),
        (b"{0:8", b"{}Z"),
        (b"KC", b"Z"),  # on the button page Z ends the rotation
        (b"KCJ", b"KJZ"),  # §13: after J a rotation goes on through Z
        (b"KGI", b"KIZ"),  # back to the page the host was on
        (b"KCJZ", b"KJZ"),
        (b"KCJA", b"Z"),  # a direction letter ended it
        (b"KCAJ", b"Z"),  # another button ended it
        (b"KC\x03J", b"Z"),  # a raw byte is not C on the button page: it stops
        (b"KCJ{0:8", b"{}KJZ"),
    ],
)
def test_the_stop_ends_frames_and_latched_rotations(sent: bytes, stop: bytes) -> None:
    end = SessionEnd()
    end.sent(sent)
    assert end.stop == stop


def test_the_stop_says_what_it_does() -> None:
    end = SessionEnd()
    assert end.stop_text == "stop"
    end.sent(b"KCJ{0:8")
    assert end.stop_text == (
        "closes the open frame, ends a button-page rotation (K), back to J, then stop"
    )
    end.sent(end.stop)
    assert end.stop == b"Z"
