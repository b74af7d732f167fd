"""A pyserial port with no modem lines: what appmode's own ports (`sim://`, `zenoh://`)
have in place of a UART's DTR, RTS, CTS, DSR, RI, CD and break."""

from __future__ import annotations

from serial import SerialBase


class Modemless(SerialBase):  # type: ignore[misc]  # pyserial has no types
    """Sets of the modem lines do nothing; reads say a link that is always ready."""

    def _update_dtr_state(self) -> None:
        """No modem lines."""

    def _update_rts_state(self) -> None:
        """No modem lines."""

    def _update_break_state(self) -> None:
        """No break."""

    @property
    def cts(self) -> bool:
        return True

    @property
    def dsr(self) -> bool:
        return True

    @property
    def ri(self) -> bool:
        return False

    @property
    def cd(self) -> bool:
        return True
