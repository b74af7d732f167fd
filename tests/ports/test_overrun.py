"""Issue 28.3: a served port nobody reads drops what the board sends, as a UART does,
and says so; it never keeps bytes to retry (which woke the server every 2 ms)."""

from __future__ import annotations

import os
import selectors
import time

from appmode.ports.endpoints import Overrun, PtyEndpoint


def test_a_pty_nobody_reads_drops_and_says_so_then_resumes() -> None:
    said: list[str] = []
    sel = selectors.DefaultSelector()
    endpoint = PtyEndpoint(sel, said.append)
    try:
        chunk = b"{A0:0:0:0}$" * 100
        dropping = f"nobody reads {endpoint.url}: what the board sends is dropped"

        def fill() -> None:
            for _ in range(1000):  # 1.1 MB: far more than a pty holds
                endpoint.write(chunk)
                if said and said[-1] == dropping:
                    return

        fill()
        assert said == [dropping]
        time.sleep(0.3)  # the kernel moves what the master holds on to the slave's side
        fill()  # full again (a drain meanwhile says "read again" first)
        told = len(said)
        for _ in range(3):
            endpoint.write(chunk)  # dropped too: nothing more is said
        assert len(said) == told and said[-1] == dropping
        client = os.open(endpoint.url, os.O_RDWR | os.O_NOCTTY | os.O_NONBLOCK)
        try:
            while True:  # the client reads everything that was kept
                try:
                    if not os.read(client, 65536):
                        break
                except BlockingIOError:
                    break
            endpoint.write(b"{B0:0:0:100}$")
            assert said[-1].startswith(f"{endpoint.url} is read again; ")
            assert said[-1].endswith(" bytes were dropped")
            assert os.read(client, 100) == b"{B0:0:0:100}$"
        finally:
            os.close(client)
    finally:
        endpoint.close()
        sel.close()


def test_an_overrun_writes_what_the_os_takes_and_counts_the_rest() -> None:
    said: list[str] = []
    taken: list[bytes] = []

    def write(data: bytes) -> int:
        if len(b"".join(taken)) >= 6:
            raise BlockingIOError
        taken.append(data[:4])
        return min(4, len(data))

    overrun = Overrun(said.append, "the port")
    overrun.write(b"0123456789", write)
    assert b"".join(taken) == b"01234567" and overrun.dropped == 2
    assert said == ["nobody reads the port: what the board sends is dropped"]
