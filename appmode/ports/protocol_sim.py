"""pyserial looks up `sim://` here (serial.protocol_handler_packages)."""

from appmode.ports.sim import SimSerial as Serial

__all__ = ["Serial"]
