"""Views of events: the fast JSON line is exactly what json.dumps writes of to_json, and
escape() is the table of the transcript format, byte by byte."""

from __future__ import annotations

import json

from hypothesis import given
from hypothesis import strategies as st

from appmode.protocol.app_decoders import BoardDecoder, HostDecoder
from appmode.protocol.escaping import _TABLE, escape, unescape
from appmode.protocol.render import json_line, to_json

RECORDISH = st.lists(
    st.sampled_from([b"{A", b"{B", b"{C", b"1", b"-", b":", b"}", b"$", b'"', b"\\", b"\x00"])
    | st.binary(max_size=4)
).map(b"".join)


@given(RECORDISH)
def test_json_line_is_json_dumps_of_to_json(data: bytes) -> None:
    for decoder in (BoardDecoder(), HostDecoder()):
        for event in [*decoder.feed(data), *decoder.flush()]:
            assert json_line(event) == json.dumps(to_json(event), ensure_ascii=False)


@given(st.binary())
def test_escape_is_the_table_byte_by_byte(data: bytes) -> None:
    assert escape(data) == "".join(_TABLE[b] for b in data)
    assert unescape(escape(data)) == data


def test_json_keys_name_every_key_to_json_writes() -> None:
    from appmode.protocol import app_decoders
    from appmode.protocol.render import json_keys, to_json

    events = [
        *app_decoders.BoardDecoder().feed(
            b"{A1:2:3:4}${B1:2:3:4}${C1:2:3:4:5:6:7:8:9}${D1:2}$x{A1"
        ),
        *app_decoders.BoardDecoder().flush(),
        *app_decoders.HostDecoder().feed(b"AZJ{Q:P}{Q;W}{0:800}{0:x}\x01{" + b"9" * 60 + b"}"),
        *app_decoders.HostDecoder().flush(),
    ]
    kinds = {to_json(e)["kind"] for e in events}
    assert len(kinds) >= 12, kinds
    for event in events:
        assert set(to_json(event)) <= set(json_keys()), to_json(event)
