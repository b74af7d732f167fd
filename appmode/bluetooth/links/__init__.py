"""The host's links to a car's Bluetooth module: `ble://` and `bt://` as pyserial ports
(pyserial finds `protocol_ble` and `protocol_bt` here), and `scan`."""
