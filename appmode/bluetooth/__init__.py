"""Bluetooth: the car's module reached directly (`ble://` on bleak, `bt://` through BlueZ's
profile API), the nearby devices (`scan`), and a BlueZ stand-in on a private D-Bus bus
that serves the simulated board as a module (`appmode board --bluetooth`)."""
