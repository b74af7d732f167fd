"""pyserial looks up `bt://` here (serial.protocol_handler_packages)."""

from appmode.bluetooth.links.spp_port import SppSerial as Serial

__all__ = ["Serial"]
