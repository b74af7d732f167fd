"""pyserial looks up `bt://` here (serial.protocol_handler_packages)."""

from appmode.bluetooth.spp_port import SppSerial as Serial

__all__ = ["Serial"]
