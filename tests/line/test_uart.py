"""A UART reading bytes sent at another rate (line/uart.py)."""

from __future__ import annotations

from hypothesis import given
from hypothesis import strategies as st

from appmode.line.uart import BITS, misread
from appmode.protocol import app, app_decoders

RECORDS = b"{A12:-5:0:33}${B1:2:90:100}$" * 8
RATES = (1200, 2400, 4800, 9600, 19200, 38400, 57600, 115200)


def records_in(data: bytes) -> int:
    return sum(isinstance(e, app.RECORDS) for e in app_decoders.BoardDecoder().feed(data))


def test_rates_a_uart_tolerates_read_every_byte() -> None:
    for off in (9600 * 0.98, 9600 * 1.02):
        assert misread(RECORDS, 9600, round(off)) == RECORDS


def test_a_wrong_rate_reads_bytes_that_are_no_records() -> None:
    assert records_in(RECORDS) == 16
    for sent, read in ((115200, 9600), (9600, 115200), (38400, 9600), (9600, 38400)):
        out = misread(RECORDS, sent, read)
        assert out and out != RECORDS
        assert records_in(out) == 0


def test_a_faster_sender_reads_as_fewer_bytes_and_a_slower_as_more() -> None:
    assert len(misread(RECORDS, 115200, 9600)) < len(RECORDS) // 4
    assert len(misread(RECORDS, 9600, 115200)) > len(RECORDS)


@given(st.binary(max_size=200), st.sampled_from(RATES), st.sampled_from(RATES))
def test_any_bytes_at_any_rates_read_without_error(data: bytes, sent: int, read: int) -> None:
    out = misread(data, sent, read)
    assert misread(data, sent, read) == out  # a line, not a random source
    # at most one byte per falling edge the receiver can see
    assert len(out) <= len(data) * BITS
    if sent == read:
        assert out == data
