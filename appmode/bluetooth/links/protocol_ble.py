"""pyserial looks up `ble://` here (serial.protocol_handler_packages)."""

from appmode.bluetooth.links.ble_port import BleSerial as Serial

__all__ = ["Serial"]
