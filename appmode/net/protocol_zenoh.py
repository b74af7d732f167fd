"""pyserial looks up `zenoh://` here (serial.protocol_handler_packages)."""

from appmode.net.remote_port import RemoteSerial as Serial

__all__ = ["Serial"]
