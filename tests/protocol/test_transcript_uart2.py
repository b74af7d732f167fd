"""Transcripts with two ports (docs/design.md, "Contracts"): `2>` / `2<` lines of hex pairs, `??` in
expectations, APP text on UART2 in APP mode, and a recorder that follows the board."""

from __future__ import annotations

import io

import pytest
from hypothesis import given
from hypothesis import strategies as st

from appmode.protocol import control
from appmode.protocol.recorder import Recorder
from appmode.protocol.transcript import (
    TranscriptError,
    parse_transcript,
    uart2_bytes,
    uart2_payload,
)

HEAD = "# appmode transcript v1\n"


def recorded(calls: list[tuple[str, float, bytes]], system_mode: int = 0) -> list[str]:
    out = io.StringIO()
    recorder = Recorder(out)
    recorder.follow(system_mode, 0.0)
    for direction, time, data in calls:
        recorder(direction, time, data)
    recorder.close()
    return out.getvalue().splitlines()[1:]


def test_uart2_lines_are_one_frame_or_reply_a_line_in_hex() -> None:
    read = control.encode(control.read("max_speed"))
    lines = recorded(
        [
            ("2>", 0.0, read[:4]),
            ("2>", 0.01, read[4:] + read),
            ("2<", 0.02, b"#\x01\x00\x00\x01\xf4"),
        ]
    )
    assert lines == [  # each line at the time of its first byte (issue 22.12)
        "0.0000 2> FF FE 80 80 11 00 00 00 00 00",
        "0.0100 2> FF FE 80 80 11 00 00 00 00 00",
        "0.0200 2< 23 01 00 00 01 F4",
    ]


def test_the_recorder_follows_the_drive_type_for_motor_frames() -> None:
    four = control.encode(control.MotorFrame((1, 2, 3, 4)))
    setting = control.SetSetting(control.settings.BY_NAME["system_mode"], 1)
    lines = recorded([("2>", 0.0, control.encode(setting)), ("2>", 0.1, four)])
    assert lines[1] == "0.1000 2> FF FE 02 00 01 00 02 00 03 00 04 00"


def test_app_mode_text_on_uart2_is_escaped_and_never_looks_like_hex() -> None:
    lines = recorded(
        [("2>", 0.0, b"A"), ("2<", 0.1, b"{A0:0:0:0}$"), ("2>", 0.2, b"\x01\x02")],
        system_mode=0x80,
    )
    assert lines[:2] == ["0.0000 2> A", "0.1000 2< {A0:0:0:0}$"]
    assert uart2_payload(b"AZ", text=True) == "AZ"
    assert uart2_payload(b"AB", text=True) == "\\x41\\x42"  # AB is a hex byte
    assert uart2_payload(b"\xab", text=True) == "\\xab"
    assert uart2_payload(b"12", text=True) == "\\x31\\x32"  # "12" would read as a hex byte


@given(st.binary(min_size=1, max_size=40), st.booleans())
def test_uart2_payloads_read_back_as_the_same_bytes(data: bytes, text: bool) -> None:
    line = f"{HEAD}0.5 2< {uart2_payload(data, text)}\n"
    [entry] = parse_transcript(line).entries
    assert entry.data == data
    assert (uart2_bytes(entry.text) is None) == text


def test_question_marks_match_any_byte_only_in_expectations() -> None:
    [entry] = parse_transcript(f"{HEAD}0.1 2< 23 01 ?? ?? 01 F4\n").entries
    hexed = uart2_bytes(entry.text)
    assert hexed is not None and hexed[1] == bytes.fromhex("FF FF 00 00 FF FF")
    with pytest.raises(TranscriptError, match=r"<transcript>:2: '\?\?' matches a byte"):
        parse_transcript(f"{HEAD}0.1 2> FF FE ?? 00\n")


def test_unknown_directions_name_both_ports() -> None:
    with pytest.raises(TranscriptError, match="'2>' or '2<' on UART2"):
        parse_transcript(f"{HEAD}0.1 3> FF\n")


@pytest.mark.parametrize("payload", ["FF FE 0G", "ff fe 01", "FF  FE"])
def test_a_uart2_line_with_spaces_must_be_hex_pairs(payload: str) -> None:
    with pytest.raises(TranscriptError, match="neither hex pairs"):
        parse_transcript(f"{HEAD}0.1 2> {payload}\n")
